"""OpenCV's hand-eye conventions, as cell.calibration.estimate.initial uses them, on exact poses."""

from __future__ import annotations

import cv2
import numpy as np

from cell.calibration.estimate import (
    example_truth,
    flange_poses,
    hand_eye_candidates,
    initial_estimate,
    pose_error,
    reference_joints,
    simulate,
    view_joints,
)
from robots.calibration import fk_with_errors


def _exact_pairs(seed: int = 0):
    tr = example_truth(seed, kinematic=False)
    Q = view_joints(tr, 8, (0.2, 0.32), reference_joints(tr), seed=seed + 1)
    T_bt = fk_with_errors(tr.dh, tr.truth.delta, Q)
    X, Y = tr.truth.T_tool0_camera, tr.truth.T_base_target
    T_ct = np.linalg.inv(T_bt @ X) @ Y
    return tr, Q, T_bt, T_ct, X, Y


def _c(A):
    return [np.ascontiguousarray(a) for a in A]


def test_calibrate_hand_eye_takes_base_tool0_and_camera_target_and_returns_tool0_camera() -> None:
    _tr, _Q, T_bt, T_ct, X, _Y = _exact_pairs()
    R, t = cv2.calibrateHandEye(
        _c(T_bt[:, :3, :3]),
        _c(T_bt[:, :3, 3:4]),
        _c(T_ct[:, :3, :3]),
        _c(T_ct[:, :3, 3:4]),
        method=cv2.CALIB_HAND_EYE_PARK,
    )
    assert np.abs(R - X[:3, :3]).max() < 1e-9 and np.abs(t.ravel() - X[:3, 3]).max() < 1e-9


def test_robot_world_hand_eye_returns_both_poses_inverted_relative_to_our_names() -> None:
    _tr, _Q, T_bt, T_ct, X, Y = _exact_pairs()
    T_t0_b = np.linalg.inv(T_bt)
    Rw, tw, Rc, tc = cv2.calibrateRobotWorldHandEye(
        _c(T_ct[:, :3, :3]),
        _c(T_ct[:, :3, 3:4]),
        _c(T_t0_b[:, :3, :3]),
        _c(T_t0_b[:, :3, 3:4]),
        method=cv2.CALIB_ROBOT_WORLD_HAND_EYE_SHAH,
    )
    T_target_base, T_camera_tool0 = np.eye(4), np.eye(4)
    T_target_base[:3, :3], T_target_base[:3, 3] = Rw, tw.ravel()
    T_camera_tool0[:3, :3], T_camera_tool0[:3, 3] = Rc, tc.ravel()
    assert np.abs(np.linalg.inv(T_camera_tool0) - X).max() < 1e-9
    assert np.abs(np.linalg.inv(T_target_base) - Y).max() < 1e-9


def test_every_candidate_method_finds_the_exact_hand_eye() -> None:
    _tr, _Q, T_bt, T_ct, X, Y = _exact_pairs(1)
    for cand in hand_eye_candidates(T_bt, T_ct):
        dp, da = pose_error(cand.T_tool0_camera, X)
        assert dp < 1e-6 and da < 1e-6, cand.method
        assert pose_error(cand.T_base_target, Y)[0] < 1e-6, cand.method


def test_the_start_from_pnp_is_within_the_kinematic_error_of_the_truth() -> None:
    tr = example_truth(2)
    Q = view_joints(tr, 10, (0.2, 0.32), reference_joints(tr), seed=3)
    obs = simulate(tr, Q, 0.1)
    init = initial_estimate(obs, flange_poses(obs, tr.dh, np.zeros(24)))
    dp, da = pose_error(init.best.T_tool0_camera, tr.truth.T_tool0_camera)
    assert dp < 5e-3 and da < np.deg2rad(0.5)
    assert init.best.spread_m == min(c.spread_m for c in init.candidates)
