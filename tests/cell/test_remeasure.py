"""Each stop's stereo pair kept in the run directory (lossless; ``--no-images`` keeps none) and
``holecell remeasure RUN_DIR``: today's code on an old run's pairs, into a new run directory,
the old one untouched (issue 26, finding 12). The three-hole cell on the simulator."""

from __future__ import annotations

import hashlib
from pathlib import Path

import numpy as np
import pytest
from cell_fixtures import SmallCell, steady_drift

from cell.camera import cell_stereo
from cell.cli import main
from cell.link.client import ControllerClient, LinkOptions
from cell.review.audit_images import kept, load_pair, save_pair
from cell.review.store import Store
from cell.run.runner import Runner, RunOptions
from cell.run.setup import start_run
from cell.sim.session import SimCell
from cell.sim.truth import CellTruth
from cell.sim.world import WorldOptions

FAST_LINK = LinkOptions(response_timeout_s=0.05, retries=20, heartbeat_period_s=0.1)


def _run(sc: SmallCell, run_dir: Path, keep_images: bool) -> None:
    world = WorldOptions(speed=20.0, drift=steady_drift(), truth=CellTruth.zero(0))
    with SimCell.start(sc.cell, world) as sim:
        files = start_run(run_dir, sc.cell, sc.tour, "tour.json", sim.url, None)
        with ControllerClient(sim.url, FAST_LINK) as client:
            opts = RunOptions(settle_s=0.0, reference_rounds=0, keep_images=keep_images)
            try:
                assert Runner(files.cell, files.tour, files.store, client, sim.camera,
                              opts).run().status == "done"  # fmt: skip
            finally:
                files.store.close()


def _digest(folder: Path) -> dict[str, str]:
    return {str(p.relative_to(folder)): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(folder.rglob("*")) if p.is_file()}  # fmt: skip


@pytest.mark.parametrize("dtype", [np.uint8, np.uint16])
def test_a_pair_reads_back_bit_for_bit(tmp_path: Path, dtype) -> None:
    rng = np.random.default_rng(0)
    top = np.iinfo(dtype).max
    left, right = (rng.integers(0, top, (48, 64), endpoint=True).astype(dtype) for _ in "lr")
    assert save_pair(tmp_path, 3, "H1", left, right) > 0
    back = load_pair(tmp_path, 3, "H1")
    assert back is not None and back[0].dtype == dtype
    np.testing.assert_array_equal(back[0], left)
    np.testing.assert_array_equal(back[1], right)
    assert load_pair(tmp_path, 4, "H1") is None


def test_a_run_keeps_its_pairs_and_remeasure_repeats_it(
    small_cell: SmallCell, tmp_path: Path, capsys
) -> None:
    run = tmp_path / "run"
    _run(small_cell, run, keep_images=True)
    n = len(small_cell.tour.stops)
    assert kept(run)["pairs"] == n and kept(run)["bytes"] > 0
    assert main(["report", str(run)]) == 0
    assert f"images kept     {n} stereo pairs" in capsys.readouterr().out
    before = _digest(run)
    out = tmp_path / "again"
    assert main(["remeasure", str(run), "-o", str(out)]) == 0
    printed = capsys.readouterr().out
    assert _digest(run) == before  # nothing of the original run is touched
    with Store.open(run) as a, Store.open(out) as b:
        old, new = a.results(), b.results()
        assert any(e["kind"] == "remeasure" for e in b.events())
    assert [r.hole_id for r in new] == [r.hole_id for r in old]
    for r0, r1 in zip(old, new, strict=True):  # the same code on the same pair: the same result
        np.testing.assert_allclose(r1.center_part_m, r0.center_part_m, atol=1e-9)
        assert r1.diameter_m == pytest.approx(r0.diameter_m, abs=1e-9)
        assert r0.hole_id in printed
    assert (out / "report.html").is_file() and not (out / "images").exists()
    # a corrected stereo calibration moves the results: it is applied to the old pairs
    st = cell_stereo(small_cell.cell)
    focal = type(st)(st.image_size, st.K_left * [[1.001], [1.001], [1]], st.dist_left,
                     st.K_right * [[1.001], [1.001], [1]], st.dist_right, st.R, st.T)  # fmt: skip
    focal.save(tmp_path / "stereo_corrected.json")
    out2 = tmp_path / "corrected"
    assert main(["remeasure", str(run), "-o", str(out2), "--stereo",
                 str(tmp_path / "stereo_corrected.json")]) == 0  # fmt: skip
    with Store.open(out2) as b:
        moved = [abs(r1.diameter_m - r0.diameter_m) for r0, r1 in zip(old, b.results(),
                                                                        strict=True)]  # fmt: skip
    assert min(moved) > 1e-7  # 0.1 % of focal length: a different diameter everywhere
    assert _digest(run) == before


def test_no_images_keeps_none(small_cell: SmallCell, tmp_path: Path, capsys) -> None:
    run = tmp_path / "run"
    _run(small_cell, run, keep_images=False)
    assert kept(run) is None and not (run / "images").exists()
    assert main(["remeasure", str(run), "-o", str(tmp_path / "again")]) == 0
    assert "kept as stored (no pair kept)" in capsys.readouterr().out
