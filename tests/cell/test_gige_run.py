"""A whole run through the simulated GigE Vision head (real GVCP/GVSP on loopback, inside a
private network namespace) gives the results the TCP head gives for the same seed; a fault
injected in the right camera at one stop fails that stop alone, with the reason."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from cell_fixtures import SmallCell, steady_drift
from netns import in_netns

from cell.cli import main
from cell.config import load_cell
from cell.config.load import builtin_cell_path
from cell.review.store import Store
from cell.sim.camserver import CameraServer
from cell.sim.faults import FaultPlan
from cell.sim.session import SimCell
from cell.sim.world import WorldOptions
from planner import Options, plan_tour

WORLD = WorldOptions(speed=50.0, drift=steady_drift())
#: a render of the simulated head takes up to seconds on a loaded machine: wait for it
PATIENT = "?timeout_ms=60000"


def _run(sc: SmallCell, out: Path, head_url: str, port: str) -> int:
    return main(["run", str(sc.tour_path), "--cell", str(sc.path), "--port", port,
                 "--camera", head_url, "--out", str(out), "--yes", "--quiet", "--no-record",
                 "--settle-s", "0", "--reference-rounds", "0"])  # fmt: skip


def _results(run_dir: Path):
    with Store.open(run_dir) as store:
        return store.results(), store.events()


def _tcp_reference(sc: SmallCell, out: Path):
    with (
        SimCell.start(sc.cell, WORLD, FaultPlan(seed=3)) as sim,
        CameraServer(sim.camera).start() as cam,
    ):
        assert _run(sc, out, cam.url, sim.url) == 0
    return _results(out)[0]


def _same(a, b) -> None:
    assert a.hole_id == b.hole_id and a.status == b.status
    np.testing.assert_allclose(a.center_part_m, b.center_part_m, atol=1e-12)
    assert abs(a.diameter_m - b.diameter_m) < 1e-12


@in_netns
def test_the_gige_head_gives_the_tcp_results(small_cell: SmallCell, tmp_path: Path) -> None:
    from cell.sim.gige_head import GigeFaults, GigeHead

    tcp = _tcp_reference(small_cell, tmp_path / "tcp")
    with (
        SimCell.start(small_cell.cell, WORLD, FaultPlan(seed=3)) as sim,
        GigeHead.for_camera(sim.camera) as head,
    ):
        assert _run(small_cell, tmp_path / "gige", head.url + PATIENT, sim.url) == 0
    gige, _ = _results(tmp_path / "gige")
    assert len(gige) == len(tcp) == len(small_cell.tour.stops)
    for a, b in zip(gige, tcp, strict=True):
        _same(a, b)
    # the right camera sends half its packets at stop 1, on the first attempt and on the retry
    # (a dropped frame is the same path after a wait: tests/cell/test_gige_head.py)
    faults = GigeFaults({"incomplete": frozenset({1})})
    with (
        SimCell.start(small_cell.cell, WORLD, FaultPlan(seed=3)) as sim,
        GigeHead.for_camera(sim.camera, faults=faults) as head,
    ):
        assert _run(small_cell, tmp_path / "incomplete", head.url + PATIENT, sim.url) == 0
    faulty, events = _results(tmp_path / "incomplete")
    assert [r.status == "unmeasured" for r in faulty] == [k == 1 for k in range(len(tcp))]
    assert "no stereo pair" in faulty[1].reason and "right frame" in faulty[1].reason
    assert "retried" in faulty[1].reason
    assert any(e["kind"] == "camera" and "stop 1" in e["message"] for e in events)
    for k in (0, 2):
        _same(faulty[k], tcp[k])


def _serve(*args: str) -> tuple[subprocess.Popen, str, str]:
    """``holecell sim ARGS`` in a child process; its controller port and camera URL."""
    env = dict(os.environ, PYTHONUNBUFFERED="1")
    p = subprocess.Popen([sys.executable, "-m", "cell.cli", "sim", *args], env=env,
                         stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)  # fmt: skip
    urls: dict[str, str] = {}
    while len(urls) < 2:
        line = p.stdout.readline()
        assert line, f"holecell sim ended: {p.wait()}"
        word, _, value = line.partition(" ")
        if word in ("controller", "camera"):
            urls[word] = value.strip()
    return p, urls["controller"], urls["camera"]


@pytest.mark.slow
@in_netns
def test_the_builtin_tour_through_holecell_sim_gige_matches_tcp(tmp_path: Path) -> None:
    cell_path = builtin_cell_path()
    tour = plan_tour(load_cell(cell_path), Options(seed=1))
    tour_path = tour.save(tmp_path / "tour.json")
    results = {}
    for transport in ("tcp", "gige"):
        sim, port, camera = _serve(
            "--seed",
            "5",
            "--speed",
            "20",
            "--drift-offset-s",
            "1e7",
            "--camera-transport",
            transport,
        )  # warm: no drift
        try:
            if transport == "gige":
                assert camera == "gige://127.0.0.1,127.0.0.2"
                camera += PATIENT
            out = tmp_path / transport
            code = main(["run", str(tour_path), "--cell", str(cell_path), "--port", port,
                         "--camera", camera, "--out", str(out), "--yes", "--quiet",
                         "--no-record", "--settle-s", "0", "--reference-rounds", "0"])  # fmt: skip
            assert code == 0
        finally:
            sim.terminate()
            sim.wait(timeout=30)
        results[transport] = _results(out)[0]
    assert len(results["gige"]) == len(tour.stops) > 20
    for a, b in zip(results["gige"], results["tcp"], strict=True):
        assert a.hole_id == b.hole_id and a.status == b.status
        np.testing.assert_allclose(a.center_part_m, b.center_part_m, atol=1e-9)
