"""A referenced run on the simulator, end to end through images: the markers are rendered into
every hole's pair, detected and identified, each stop is resected against the surveyed network
and its hole carried into the part by that pose. A marker moved after the survey is refused by
id; a stop left with three markers falls back to the arm and is flagged.

The survey here is adjusted from the true markers projected through the true head (the survey's
own images are the slow test's and the demo's); everything after it is the real run."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from cell.camera import cell_stereo
from cell.link.client import ControllerClient
from cell.referencing import save_markers, survey
from cell.referencing.layout import markers_seen_per_hole
from cell.referencing.network import load_network
from cell.referencing.survey.plan import survey_views
from cell.referencing.synthetic import observe
from cell.run.runner import Runner, RunOptions
from cell.run.setup import start_run
from cell.sim.camera import true_head
from cell.sim.session import SimCell
from cell.sim.truth import CellTruth
from cell.sim.world import SimWorld, WorldOptions
from planner import Options, plan_tour
from robots.transforms import kabsch

SEED = 5


def _truth(cell, moved: dict | None = None) -> CellTruth:
    """An arm as calibrated (its repeatability left), the head off its calibration, the
    markers off nominal (``moved``: offsets after the survey); the part where the cell file
    puts it, so that the fixture frame's error is the measurement's."""
    drawn = CellTruth.drawn(SEED, cell)
    t = replace(CellTruth.zero(SEED), repeatability_rp_m=drawn.repeatability_rp_m,
                calibration_sigma_scale=1.0, part_temperature_c=20.0)  # fmt: skip
    if moved:
        world = SimWorld(cell, WorldOptions(truth=t))
        errors = {}
        for mid, d in moved.items():
            k = world.markers.ids.index(mid)
            e = world.markers.true[k] - world.markers.nominal[k]
            on_part = not world.markers.on_fixture[k]
            R = cell.T_cell_part()[:3, :3] if on_part else np.eye(3)
            errors[mid] = tuple(R.T @ e + np.asarray(d, float))  # part frame for a part marker
        t = replace(t, marker_errors=errors)
    return t


@pytest.fixture(scope="module")
def surveyed(small_cell, tmp_path_factory) -> Path:
    stereo = cell_stereo(small_cell)
    t = _truth(small_cell)
    world = SimWorld(small_cell, WorldOptions(truth=t))
    head = true_head(stereo, t.calibration_sigma_scale, t.seed)
    rng = np.random.default_rng(SEED)
    views = [observe(world.markers, head, T, vid, 0.05, rng, T)
             for vid, T in survey_views(small_cell, stereo)]  # fmt: skip
    res = survey(small_cell, stereo, views)
    return save_markers(tmp_path_factory.mktemp("survey") / "markers.json", res, small_cell, stereo)


@pytest.fixture(scope="module")
def tour(small_cell):
    return plan_tour(small_cell, Options(seed=1))


def _run(cell, tour, truth, markers: Path, run_dir: Path):
    network = load_network(markers, cell, cell_stereo(cell))
    with SimCell.start(cell, WorldOptions(speed=20.0, truth=truth)) as sim:
        files = start_run(run_dir, cell, tour, "tour.json", sim.url, None)
        client = ControllerClient(sim.url)
        client.connect()
        try:
            runner = Runner(
                files.cell,
                files.tour,
                files.store,
                client,
                sim.camera,
                RunOptions(settle_s=0.0, reference_rounds=0),
                markers=network,
            )
            runner.run()
            results = files.store.results()
            return results, files.store.events(), _best_fit_error(cell, sim.world, results)
        finally:
            client.close()
            files.store.close()


def _best_fit_error(cell, world, results) -> np.ndarray:
    """In-plane distances (m) of the measured centres from the true ones after a rigid best
    fit: the survey's gauge (its fixture markers fitted to their nominal places, each 0.3 mm
    off) moves the whole network, and so the cell frame, by a rigid motion."""
    T = cell.T_cell_part()
    M = np.array([T[:3, :3] @ r.center_part_m + T[:3, 3] for r in results])
    Q = np.array([world.holes_at_temperature[r.hole_id].position_m for r in results])
    N = np.array([world.holes_at_temperature[r.hole_id].normal for r in results])
    R, t, _ = kabsch(M, Q[None])
    d = M @ R[0].T + t[0] - Q
    return np.linalg.norm(d - np.sum(d * N, axis=1)[:, None] * N, axis=1)


def test_every_stop_is_located_against_the_markers(small_cell, tour, surveyed, tmp_path):
    results, events, err = _run(small_cell, tour, _truth(small_cell), surveyed, tmp_path / "r")
    assert all(r.status == "ok" for r in results), [(r.hole_id, r.reason) for r in results]
    refs = [r.extra["referencing"] for r in results]
    assert all(x["referenced"] and len(x["markers"]) >= 4 and not x["refused"] for x in refs)
    assert all(x["arm_disagreement_m"] < 1e-3 for x in refs)
    rows = {c["name"] for r in results for c in r.budget["components"]}
    assert {"resection", "survey_markers"} <= rows
    assert not rows & {"robot_repeatability", "thermal_model", "cell_calibration"}
    assert err.max() < 25e-6, err
    assert any("referenced against" in e["message"] for e in events if e["kind"] == "referencing")


def test_a_moved_marker_is_refused_by_id_and_three_markers_fall_back(small_cell, tour, surveyed,
                                                                    tmp_path):  # fmt: skip
    seen = markers_seen_per_hole(small_cell, cell_stereo(small_cell))
    many = next(h for h in tour.hole_order if len(seen[h]) >= 6)
    four = next(h for h in tour.hole_order if len(seen[h]) == 4 and h != many)
    moved = {seen[many][0]: (0.0, 0.0, 2e-3)}  # knocked 2 mm after the survey
    lone = next(m for m in seen[four] if all(m not in seen[h] for h in seen if h != four))
    moved[lone] = (2e-3, 0.0, 0.0)
    results, events, _ = _run(small_cell, tour, _truth(small_cell, moved), surveyed,
                              tmp_path / "r")  # fmt: skip
    by = {r.hole_id: r.extra["referencing"] for r in results}
    assert by[many]["referenced"] and seen[many][0] in by[many]["refused"]
    assert "moved since the survey" in by[many]["refused"][seen[many][0]]
    assert not by[four]["referenced"] and "3 usable markers" in by[four]["reason"]
    fallback = next(r for r in results if r.hole_id == four)
    assert "robot_repeatability" in {c["name"] for c in fallback.budget["components"]}
    logged = " ".join(e["message"] for e in events if e["kind"] == "referencing")
    assert f"{four}: not referenced" in logged and seen[many][0] in logged
