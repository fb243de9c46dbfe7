"""The information-based design of the calibration views (cell.calibration.plan.design)."""

from __future__ import annotations

import numpy as np
import pytest

from cell.calibration.estimate import Cameras, column_names, perturb_pose
from cell.calibration.plan import (
    TargetGeometry,
    board_of,
    design_rows,
    information_model,
    point_sensitivity,
    predict_sigmas,
    stereo_model,
)
from cell.calibration.plan.design import _state
from cell.camera import cell_stereo
from cell.config import load_builtin_cell
from planner.calibration import candidate_views, preselect
from robots.calibration import fk_with_errors
from robots.transforms import make_transform, rpy_to_matrix

TARGET = TargetGeometry(
    "chessboard", 9, 7, 0.01, make_transform(rpy_to_matrix([np.pi, 0, 0]), [0.9, -0.45, 0.381])
)


@pytest.fixture(scope="module")
def setup():
    cell = load_builtin_cell()
    stereo = cell_stereo(cell)
    head = stereo_model(stereo)
    cands = candidate_views(cell.build_arm(), board_of(TARGET), head, 0.25, cell.home_q())
    cands = cands.subset(np.arange(0, len(cands), 3))  # a third: enough, and fast
    stops = np.array([cell.home_q(), cell.home_q() + np.array([0.3, 0.2, -0.1, 0.4, 0.3, -0.5])])
    model = information_model(cell, TARGET, stereo, cands, stops)
    return cell, stereo, head, cands, stops, model


def test_the_candidates_pixels_are_the_adjustments_model(setup) -> None:
    *_, model = setup
    assert model.residual_px < 1e-6
    assert not any(c in model.columns for c in model.fixed)  # structural terms left out
    assert model.blocks.shape == (len(setup[3]), len(model.columns), len(model.columns))


def test_point_sensitivity_matches_finite_differences(setup) -> None:
    cell, stereo, head, _, stops, _ = setup
    dh = cell.build_robot().dh
    state = _state(cell, TARGET, Cameras.from_stereo(stereo), head.T_tcp_left)
    x = np.array([0.01, -0.02, 0.25])
    H = point_sensitivity(dh, state, stops, x)
    cols = column_names(True, True)

    def point(T_X, delta):
        T = fk_with_errors(dh, delta, stops) @ T_X
        return T[:, :3, :3] @ x + T[:, :3, 3]

    base = point(state.T_tool0_camera, np.zeros(24))
    h = 1e-6
    for k, name in enumerate(cols):
        if name.startswith("T_tool0_camera."):
            e = np.zeros(6)
            e[k] = h
            moved = point(perturb_pose(state.T_tool0_camera, e), np.zeros(24))
        elif name.startswith("dh."):
            d = np.zeros(24)
            d[k - cols.index("dh.a1_m")] = h
            moved = point(state.T_tool0_camera, d)
        else:
            assert np.all(H[:, :, k] == 0)  # the target and the stereo extrinsics: no motion
            continue
        assert np.allclose((moved - base) / h, H[:, :, k], atol=1e-4), name


def test_predicted_sigma_scales_with_the_corner_noise(setup) -> None:
    cell, stereo, _, cands, stops, model = setup
    rows = list(range(0, len(cands), max(len(cands) // 12, 1)))[:12]
    a = predict_sigmas(model, rows)
    twice = information_model(cell, TARGET, stereo, cands, stops, sigma_px=2 * model.sigma_px)
    b = predict_sigmas(twice, rows)
    assert b["view_point_sigma_m"] == pytest.approx(2 * a["view_point_sigma_m"], rel=1e-6)
    assert set(a["sigma"]) | set(a["fixed"]) >= set(model.columns)
    assert a["hand_eye_sigma_m"] > 0 and a["tcp_sigma_m"] > 0


def test_the_tcp_design_beats_the_geometric_one_on_its_aim(setup) -> None:
    _, _, head, cands, _, model = setup
    box = (np.min(cands.q, axis=0), np.max(cands.q, axis=0))
    geometric = preselect(cands, 10, head.image_size, box)
    tcp = design_rows(model, 10, "tcp", [geometric])
    assert len(set(tcp)) == 10
    ours = predict_sigmas(model, tcp)["view_point_sigma_m"]
    assert ours < predict_sigmas(model, geometric)["view_point_sigma_m"]


def test_repeatability_enters_as_a_rigid_shift_per_view(setup) -> None:
    cell, stereo, _, cands, stops, model = setup
    rep = information_model(cell, TARGET, stereo, cands, stops, repeatability_sigma_m=11e-6)
    k = 5
    Jv = rep.jacobians([k])[0]
    Jt = Jv[:, rep.shift_columns]
    cov = rep.sigma_px**2 * np.eye(len(Jv)) + rep.repeatability_sigma_m**2 * Jt @ Jt.T
    direct = Jv.T @ np.linalg.solve(cov, Jv)
    assert np.allclose(rep.blocks[k], direct, rtol=1e-6, atol=1e-6 * np.abs(direct).max())
    rows = list(range(0, len(cands), max(len(cands) // 12, 1)))[:12]
    assert (
        predict_sigmas(rep, rows)["view_point_sigma_m"]
        > predict_sigmas(model, rows)["view_point_sigma_m"]
    )
