"""Calibration views: candidates, the geometric pre-selection, the information design, the tour."""

from __future__ import annotations

import itertools
import json

import numpy as np
import pytest

from cell.calibration.plan import stereo_model
from cell.config import load_builtin_cell
from measure.synth import standard_stereo
from measure.target import TargetSpec
from planner import Options, TourFileError
from planner.calibration import (
    Board,
    CalibrationTour,
    CandidateOptions,
    NoCalibrationViewError,
    candidate_views,
    choose_by_information,
    design_value,
    geometry_score,
    load_caltour,
    plan_view_tour,
    preselect,
    view_ids,
    view_metadata,
)
from planner.calibration.select import grid_cells, joint_bins
from robots.transforms import invert, make_transform, rpy_to_matrix

#: a board we place ourselves: flat on the fixture table, beside the part, printed side up
BOARD_XYZ = (0.9, -0.45, 0.381)
#: the board frame looks into the plate (OpenCV): printed face up is a half-turn about x
FACE_UP = rpy_to_matrix([np.pi, 0.0, 0.0])


@pytest.fixture(scope="module")
def setup():
    cell = load_builtin_cell()
    arm = cell.build_arm()
    head = stereo_model(standard_stereo())
    spec = TargetSpec("chessboard", 9, 7, 0.01)
    board = Board(make_transform(FACE_UP, BOARD_XYZ), spec.object_points())
    cands = candidate_views(arm, board, head, cell.tool.standoff_m, cell.home_q())
    return cell, arm, head, board, cands


def test_every_candidate_shows_the_whole_board_to_both_cameras(setup) -> None:
    cell, arm, head, board, c = setup
    o = CandidateOptions()
    w, h = head.image_size
    margin = o.margin_frac * w
    assert len(c) > 100
    for k in range(0, len(c), 7):
        T_cell_tcp = arm.fk(c.q[k], "tcp")
        assert np.allclose(T_cell_tcp, c.T_cell_tcp[k], atol=1e-6)
        assert arm.within_limits(c.q[k]) and not arm.in_collision(c.q[k])
        for T_tcp_cam, project, T_cam_target, uv in (
            (head.T_tcp_left, head.project_left, c.T_left_target[k], c.uv_left[k]),
            (head.T_tcp_right, head.project_right, c.T_right_target[k], c.uv_right[k]),
        ):
            T = invert(T_cell_tcp @ T_tcp_cam) @ board.T_cell_target
            assert np.allclose(T, T_cam_target, atol=1e-6)
            P = board.points_target @ T[:3, :3].T + T[:3, 3]
            s = cell.tool.standoff_m
            assert P[:, 2].min() >= o.depth_range[0] * s and P[:, 2].max() <= o.depth_range[1] * s
            assert np.allclose(project(P), uv)
            assert uv.min() >= margin and uv[:, 0].max() <= w - 1 - margin
            assert uv[:, 1].max() <= h - 1 - margin
        assert c.tilt_rad[k] <= np.radians(o.max_tilt_deg) + 1e-9
        for v in c.variants[k]:  # the 2pi variants: the same arm geometry
            assert np.allclose(arm.fk(v, "tcp"), T_cell_tcp, atol=1e-6)
    assert c.coverage.min() > 0 and c.coverage.max() < 1


def test_a_board_facing_away_has_no_view_and_says_why(setup) -> None:
    cell, arm, head, _, _ = setup
    spec = TargetSpec("chessboard", 9, 7, 0.01)
    down = Board(make_transform(np.eye(3), BOARD_XYZ), spec.object_points())
    with pytest.raises(NoCalibrationViewError, match="calibration_target: no feasible") as exc:
        candidate_views(arm, down, head, cell.tool.standoff_m, cell.home_q())
    assert exc.value.reasons  # counted by reason (inside the table, behind the board, ...)


def test_preselection_spreads_rotations_image_and_joints(setup) -> None:
    _, _, head, _, c = setup
    box = (np.min(c.q, axis=0), np.max(c.q, axis=0))
    rows = preselect(c, 10, head.image_size, box)
    assert len(set(rows)) == 10
    chosen = geometry_score(c, rows, head.image_size, box)
    assert chosen.min_rotation_rad > np.radians(20)
    assert chosen.axis_eigen_min > 0.3  # rotation axes far from parallel
    assert chosen.image > 0.8
    rng = np.random.default_rng(0)
    for _ in range(5):  # beats random sets of the same size on its own score
        rand = list(rng.choice(len(c), 10, replace=False))
        assert chosen.total > geometry_score(c, rand, head.image_size, box).total


def test_grid_and_joint_cells() -> None:
    uv = np.array([[[0.0, 0.0], [99.0, 49.0]], [[50.0, 10.0], [50.0, 10.0]]])
    cells = grid_cells(uv, (100, 50), (2, 2))
    assert cells.tolist() == [[True, False, False, True], [False, True, False, False]]
    q = np.array([[0.0, 0.5], [1.0, 2.0]])
    bins = joint_bins(q, (np.zeros(2), np.ones(2)), 2)
    assert bins.tolist() == [[True, False, False, True], [False, True, False, False]]


def _brute(blocks, n, prior, W):
    best = min(itertools.combinations(range(len(blocks)), n),
               key=lambda r: design_value(blocks, list(r), prior, W))  # fmt: skip
    return design_value(blocks, list(best), prior, W)


@pytest.mark.parametrize("weighted", [False, True])
def test_information_design_finds_the_best_small_design(weighted: bool) -> None:
    rng = np.random.default_rng(3)
    p, m, n = 4, 9, 3
    blocks = []
    for _ in range(m):
        J = rng.normal(size=(2, p)) * rng.uniform(0.2, 2.0, size=p)
        blocks.append(J.T @ J)
    blocks = np.array(blocks)
    prior = 1e-3 * np.eye(p)
    W = np.diag([1.0, 0.0, 4.0, 0.5]) if weighted else None
    rows = choose_by_information(blocks, n, prior, W)
    assert len(set(rows)) == n
    best = _brute(blocks, n, prior, W)
    assert design_value(blocks, rows, prior, W) <= best + 1e-9 * abs(best)


def test_the_view_tour_visits_every_view_and_round_trips(setup, tmp_path) -> None:
    cell, _, head, _, c = setup
    box = (np.min(c.q, axis=0), np.max(c.q, axis=0))
    rows = preselect(c, 4, head.image_size, box)
    chosen = c.subset(rows)
    ids = view_ids(4)
    tour = plan_view_tour(cell, chosen, ids, Options(seed=0))
    assert sorted(s.hole_id for s in tour.stops) == ids
    for s in tour.stops:
        k = ids.index(s.hole_id)
        assert np.min(np.abs(chosen.variants[k] - np.array(s.q)).max(axis=1)) < 1e-9
    assert tour.cycle_time_s > 4 * Options().dwell_s
    cal = CalibrationTour(tour, {"pattern": "chessboard"}, view_metadata(chosen, ids),
                          {"criterion": "geometric"}, {"sigma": {}})  # fmt: skip
    path = cal.save(tmp_path / "caltour.json")
    back = load_caltour(path)
    assert back.tour.hole_order == tour.hole_order
    assert back.views[0]["T_left_target"]["xyz"] == cal.views[0]["T_left_target"]["xyz"]
    data = json.loads(path.read_text())
    tour.save(tmp_path / "tour.json")  # a hole tour is not a calibration tour
    with pytest.raises(TourFileError, match="format"):
        load_caltour(tmp_path / "tour.json")
    data["calibration"]["views"] = data["calibration"]["views"][:-1]
    (tmp_path / "bad.json").write_text(json.dumps(data))
    with pytest.raises(TourFileError, match=r"calibration\.views"):
        load_caltour(tmp_path / "bad.json")
