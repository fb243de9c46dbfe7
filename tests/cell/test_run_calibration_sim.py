"""Runs on the simulated cell with a cell calibration: the small cell by default (three holes,
no warm-up), the whole demo with the slow marker."""

from __future__ import annotations

from dataclasses import replace
from itertools import combinations
from pathlib import Path

import numpy as np
import pytest
from cell_fixtures import SmallCell, steady_drift

from cell.calibration.file import save_calibration
from cell.calibration.use import load_run_calibration, store_calibration
from cell.camera import cell_stereo
from cell.demo.sim_calibration import design_views, simulated_calibration
from cell.link.client import ControllerClient, LinkOptions
from cell.review.report import write_report
from cell.run.runner import Runner, RunOptions
from cell.run.setup import start_run
from cell.sim.session import SimCell
from cell.sim.truth import CellTruth
from cell.sim.world import WorldOptions
from robots.transforms import invert

FAST_LINK = LinkOptions(response_timeout_s=0.05, retries=20, heartbeat_period_s=0.1)


def _run(sc: SmallCell, run_dir: Path, sim: SimCell, calibration):
    files = start_run(run_dir, sc.cell, sc.tour, "tour.json", sim.url, None)
    if calibration is not None:
        store_calibration(calibration, run_dir)
    with ControllerClient(sim.url, FAST_LINK) as client:
        runner = Runner(files.cell, files.tour, files.store, client, sim.camera,
                        RunOptions(settle_s=0.0, reference_rounds=0,
                                   part_temperature_c=sim.world.part_reading_c()),
                        None, None, None, None,
                        calibration)  # fmt: skip
        try:
            return runner.run(), files.store.results(), files.store.events()
        finally:
            files.store.close()


def _distance_errors(world, results) -> np.ndarray:
    """Measured minus true distances (m) between every pair of holes: free of the base's and
    the part's placement, which no arm calibration sees."""
    T = invert(world.T_cell_part)
    true = {r.hole_id: T[:3, :3] @ world.holes[r.hole_id].position_m + T[:3, 3] for r in results}
    meas = {r.hole_id: np.asarray(r.center_part_m) for r in results}
    return np.array([np.linalg.norm(meas[a] - meas[b]) - np.linalg.norm(true[a] - true[b])
                     for a, b in combinations(sorted(meas), 2)])  # fmt: skip


def test_a_run_with_the_calibration_measures_the_small_cell(
    small_cell: SmallCell, tmp_path: Path
) -> None:
    """The realistic truth of seed 5 (mm-sized D-H, head, base, part and plate errors) without
    the arm's repeatability and with the head exactly as calibrated (those two limit a run,
    not the calibration: benchmarks/demo_calibrated.py): the calibrated run's hole-to-hole
    distances are right to a few um, the nominal run's are off by a millimetre or more; the
    budget holds the calibration's row, the stops were corrected and the report names the
    calibration."""
    cell = small_cell.cell
    truth = replace(CellTruth.drawn(5, cell), repeatability_rp_m=0.0, calibration_sigma_scale=0.0)
    world = WorldOptions(speed=20.0, drift=steady_drift(), truth=truth, drift_offset_s=0.0)
    st = cell_stereo(cell)
    with SimCell.start(cell, world) as sim:
        q = design_views(cell, st, np.array([s.q for s in small_cell.tour.stops]), 30)
        res = simulated_calibration(cell, sim.world.true_geometry(), st,
                                    truth.repeatability_rp_m, q, seed=5)  # fmt: skip
        path = tmp_path / "cellcal.json"
        save_calibration(res.calibration, path)
        rc = load_run_calibration(path, cell, cell.build_robot(), st)
        result, stored, events = _run(small_cell, tmp_path / "cal", sim, rc)
        _, nominal, _ = _run(small_cell, tmp_path / "nominal", sim, None)
        cal_err = _distance_errors(sim.world, stored)
        nom_err = _distance_errors(sim.world, nominal)
    assert result.status == "done" and all(r.center_part_m is not None for r in stored)
    assert np.abs(cal_err).max() < 10e-6  # measured: 0.1, 1.4, 2.9 um
    assert np.abs(nom_err).min() > 500e-6  # measured: 1.07 to 1.73 mm
    for r in stored:
        names = [c["name"] for c in r.budget["components"]]
        assert "cell_calibration" in names
        assert np.shape(r.extra["cell_calibration_factor_part"]) == (
            3,
            len(rc.calibration.parameter_names),
        )
    assert all("cell_calibration" not in [c["name"] for c in r.budget["components"]]
               for r in nominal)  # fmt: skip
    note = next(e["message"] for e in events if e["kind"] == "calibration")
    assert "stops corrected by up to" in note and str(path) in note
    summary = write_report(tmp_path / "cal")
    assert summary["calibration"]["created_utc"] == res.calibration.created_utc
    assert "Cell calibration" in (tmp_path / "cal" / "report.html").read_text()


@pytest.mark.slow
def test_the_demo_calibrates_first_and_measures_in_the_datum_frame(tmp_path: Path) -> None:
    from cell.demo.demo import DemoOptions, run_demo

    res = run_demo(tmp_path / "run", DemoOptions(seed=1))
    assert res.calibration is not None and res.calibration.hand_eye_error_m < 0.05e-3
    assert res.datum.n == 41 and res.datum.best_fit_rms_in_plane_m < 60e-6
    assert res.truth.rms_in_plane_m > 300e-6  # the fixture frame holds the placements
    nocal = run_demo(tmp_path / "nocal", DemoOptions(seed=1, calibrate=False))
    assert nocal.datum.best_fit_rms_in_plane_m > 5 * res.datum.best_fit_rms_in_plane_m
