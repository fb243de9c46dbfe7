"""The survey's views rendered and detected in worker processes give what one process gives:
the simulated head's snapshot renders the pair its capture renders, and the views of a few
snapshots are the same, in the same order, with 0 or 2 workers."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from cell.camera.workers import executor
from cell.config.markers import marker_codes, marker_in_cell
from cell.referencing.detection import detect_pair
from cell.referencing.survey.capture import observe_view
from cell.referencing.survey.plan import survey_views
from cell.run.ahead import PairsAhead
from cell.sim.camera import SimCamera
from cell.sim.truth import CellTruth
from cell.sim.world import SimWorld, WorldOptions
from robots.transforms import invert


class _Arm:
    """A controller that sits at one joint vector."""

    def __init__(self, q: np.ndarray) -> None:
        self.q = q

    def q_rad(self) -> np.ndarray:
        return self.q


@pytest.fixture(scope="module")
def scenes(small_cell, stereo):
    """Simulated heads at the first survey views the arm reaches, markers in both images."""
    truth = replace(CellTruth.drawn(4, small_cell), part_temperature_c=20.0)
    # a warm arm: its drift no longer changes with time, so every exposure of a pose is the same
    world = SimWorld(small_cell, WorldOptions(truth=truth, drift_offset_s=1e7))
    arm = world.arm
    out = []
    for vid, T_cell_left in survey_views(small_cell, stereo):
        cam = SimCamera(world, _Arm(np.zeros(6)), stereo, seed=3)
        sols = arm.ik(T_cell_left @ invert(cam._T_head_left)).solutions
        q = next((q for q in sols if not arm.in_collision(q)), None)
        if q is None:
            continue
        cam.controller = _Arm(q)
        out.append((vid, T_cell_left, cam))
        if len(out) == 3:
            break
    return out


def _geometry(cell):
    T = cell.T_cell_part()
    return {m.id: (*marker_in_cell(m, T), 0.5 * m.diameter_m) for m in cell.reference_markers}


def test_a_snapshot_renders_the_pair_the_capture_renders(scenes):
    _vid, _T, cam = scenes[0]
    before = cam.captures
    snap = cam.snapshot()
    cam.captures = before  # the same exposure again
    pair = cam.capture()
    later = snap()
    assert cam.last_truth.kind == "none"  # a survey view: markers, no hole
    np.testing.assert_array_equal(later.left, pair.left)
    np.testing.assert_array_equal(later.right, pair.right)


def test_views_from_worker_processes_equal_views_from_this_process(scenes, small_cell, stereo):
    codes = marker_codes(small_cell.reference_markers)
    geometry = _geometry(small_cell)
    results = {}
    snaps = [(vid, T, cam.snapshot()) for vid, T, cam in scenes]
    pairs = [(vid, T, s()) for vid, T, s in snaps]  # a camera without snapshots sends pairs
    for workers, sources in ((0, snaps), (2, snaps), ("2, pairs", pairs)):
        with executor(2 if workers else 0) as pool:
            jobs = [pool.submit(observe_view, s, stereo, codes, geometry, vid, T)
                    for vid, T, s in sources]  # fmt: skip
            results[workers] = [job.result()[0] for job in jobs]
    serial = results[0]
    assert sum(len(v.both()) for v in serial) >= 8  # the views see markers
    for a, b in [ab for key in (2, "2, pairs") for ab in zip(serial, results[key], strict=True)]:
        assert a.view_id == b.view_id
        for side in ("uv_left", "uv_right"):
            da, db = getattr(a, side), getattr(b, side)
            assert sorted(da) == sorted(db)
            for mid in da:
                np.testing.assert_array_equal(da[mid], db[mid])
        np.testing.assert_array_equal(a.T_cell_left_prior, b.T_cell_left_prior)


def test_a_stop_rendered_ahead_comes_with_the_markers_its_pair_shows(scenes, small_cell, stereo):
    _vid, _T, cam = scenes[1]
    codes = marker_codes(small_cell.reference_markers)
    ahead = PairsAhead(cam, None, markers=(stereo, codes))
    try:
        pair, kept, dets = ahead.capture(0, "H1").result()
    finally:
        ahead.close()
    assert not kept
    here = detect_pair(pair.left, pair.right, stereo, codes)
    assert len(dets[0]) >= 4 and len(dets[1]) >= 4
    for found, expected in zip(dets, here, strict=True):
        assert [d.code for d in found] == [d.code for d in expected]
        for a, b in zip(found, expected, strict=True):
            np.testing.assert_array_equal(a.center_px, b.center_px)
