"""Starting values of the adjustment from OpenCV: per-view PnP, then hand-eye.

``cv2.solvePnP`` gives each view's ``T_camera_target`` (left camera). With the flange poses
``T_base_tool0`` (nominal kinematics), OpenCV's hand-eye solvers give ``T_tool0_camera``:

- ``cv2.calibrateHandEye(R_gripper2base, t_gripper2base, R_target2cam, t_target2cam)`` takes
  ``T_base_tool0`` and ``T_camera_target`` and returns ``cam2gripper`` = ``T_tool0_camera``;
- ``cv2.calibrateRobotWorldHandEye(R_world2cam, t_world2cam, R_base2gripper, t_base2gripper)``
  takes ``T_camera_target`` and ``inv(T_base_tool0)`` and returns ``base2world`` =
  ``T_target_base`` and ``gripper2cam`` = ``T_camera_tool0`` (both inverted relative to
  our names; ``tests/calibration/test_calsolve_opencv.py`` holds these conventions).

Every method is tried (before OpenCV 4.10, PR #24897, Tsai, Horaud and Daniilidis failed on
some pose pairs while Park worked) and the one whose target poses ``T_base_tool0 @ X @
T_camera_target`` agree best across views is kept. The target's pose is their mean.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import cv2
import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from cell.calibration.errors import DegenerateCalibrationError
from cell.calibration.estimate.observations import CalibrationObservations

Array = NDArray[np.float64]

#: OpenCV hand-eye methods tried, by name
HAND_EYE_METHODS: dict[str, int] = {
    "park": cv2.CALIB_HAND_EYE_PARK,
    "tsai": cv2.CALIB_HAND_EYE_TSAI,
    "horaud": cv2.CALIB_HAND_EYE_HORAUD,
    "andreff": cv2.CALIB_HAND_EYE_ANDREFF,
    "daniilidis": cv2.CALIB_HAND_EYE_DANIILIDIS,
}
ROBOT_WORLD_METHODS: dict[str, int] = {
    "shah": cv2.CALIB_ROBOT_WORLD_HAND_EYE_SHAH,
    "li": cv2.CALIB_ROBOT_WORLD_HAND_EYE_LI,
}


@dataclass(frozen=True)
class HandEyeCandidate:
    """One OpenCV solution: ``T_tool0_camera``, ``T_base_target`` and how well the views agree
    (spread of the per-view target poses: RMS position m, RMS angle rad; inf when it failed)."""

    method: str
    T_tool0_camera: Array
    T_base_target: Array
    spread_m: float
    spread_rad: float
    time_s: float


@dataclass(frozen=True)
class InitialEstimate:
    """The chosen candidate, all candidates and the per-view PnP poses (V, 4, 4)."""

    best: HandEyeCandidate
    candidates: tuple[HandEyeCandidate, ...]
    T_camera_target: Array
    pnp_views: tuple[int, ...] = field(default=())


def _to_T(R: Array, t: Array) -> Array:
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = R, np.asarray(t, float).reshape(3)
    return T


def solve_pnp(obs: CalibrationObservations) -> tuple[Array, tuple[int, ...]]:
    """``T_camera_target`` (k, 4, 4) of the views whose left image saw the target, and their
    indices. Planar IPPE, refined by Levenberg-Marquardt."""
    obj = obs.target.object_points()
    K, dist = obs.cameras.left.K, obs.cameras.left.dist
    poses, index = [], []
    for i, v in enumerate(obs.views):
        if v.corners_left_px is None:
            continue
        img = np.ascontiguousarray(v.corners_left_px, float).reshape(-1, 1, 2)
        ok, rvec, tvec = cv2.solvePnP(obj, img, K, dist, flags=cv2.SOLVEPNP_IPPE)
        if not ok:
            continue
        rvec, tvec = cv2.solvePnPRefineLM(obj, img, K, dist, rvec, tvec)
        poses.append(_to_T(cv2.Rodrigues(rvec)[0], tvec))
        index.append(i)
    return np.array(poses).reshape(-1, 4, 4), tuple(index)


def mean_pose(T: Array) -> Array:
    """Mean of poses (k, 4, 4): mean position, chordal mean rotation."""
    return _to_T(Rotation.from_matrix(T[:, :3, :3]).mean().as_matrix(), T[:, :3, 3].mean(axis=0))


def _spread(T: Array) -> tuple[float, float]:
    m = mean_pose(T)
    dp = np.linalg.norm(T[:, :3, 3] - m[:3, 3], axis=1)
    da = (Rotation.from_matrix(T[:, :3, :3]) * Rotation.from_matrix(m[:3, :3]).inv()).magnitude()
    return float(np.sqrt(np.mean(dp**2))), float(np.sqrt(np.mean(da**2)))


def _candidate(method: str, X: Array, T_bt: Array, T_ct: Array, t0: float) -> HandEyeCandidate:
    if not np.all(np.isfinite(X)) or abs(np.linalg.det(X[:3, :3]) - 1.0) > 1e-6:
        return HandEyeCandidate(method, X, np.eye(4), np.inf, np.inf, time.perf_counter() - t0)
    Ys = T_bt @ X @ T_ct
    sp_m, sp_r = _spread(Ys)
    return HandEyeCandidate(method, X, mean_pose(Ys), sp_m, sp_r, time.perf_counter() - t0)


def _mats(A: Array) -> list[Array]:
    """OpenCV's input: a list of contiguous 3x3 rotations or 3x1 translations."""
    return [np.ascontiguousarray(a, dtype=np.float64) for a in A]


def hand_eye_candidates(
    T_base_tool0: Array, T_camera_target: Array
) -> tuple[HandEyeCandidate, ...]:
    """Every OpenCV hand-eye solution of the pose pairs (k, 4, 4) each."""
    out = []
    Rg, tg = _mats(T_base_tool0[:, :3, :3]), _mats(T_base_tool0[:, :3, 3:4])
    Rc, tc = _mats(T_camera_target[:, :3, :3]), _mats(T_camera_target[:, :3, 3:4])
    for name, flag in HAND_EYE_METHODS.items():
        t0 = time.perf_counter()
        try:
            R, t = cv2.calibrateHandEye(Rg, tg, Rc, tc, method=flag)
            X = _to_T(R, t)
        except cv2.error:
            X = np.full((4, 4), np.nan)
        out.append(_candidate(name, X, T_base_tool0, T_camera_target, t0))
    T_tool0_base = np.linalg.inv(T_base_tool0)
    for name, flag in ROBOT_WORLD_METHODS.items():
        t0 = time.perf_counter()
        try:
            _Rw, _tw, R_c_g, t_c_g = cv2.calibrateRobotWorldHandEye(
                Rc,
                tc,
                _mats(T_tool0_base[:, :3, :3]),
                _mats(T_tool0_base[:, :3, 3:4]),
                method=flag,
            )
            X = np.linalg.inv(_to_T(R_c_g, t_c_g))
        except cv2.error:
            X = np.full((4, 4), np.nan)
        out.append(_candidate(name, X, T_base_tool0, T_camera_target, t0))
    return tuple(out)


def initial_estimate(obs: CalibrationObservations, T_base_tool0: Array) -> InitialEstimate:
    """PnP per view, every OpenCV hand-eye method, the most consistent one kept.

    ``T_base_tool0`` (V, 4, 4): flange poses of all views (nominal kinematics).
    """
    T_ct, index = solve_pnp(obs)
    if len(index) < 3:
        raise DegenerateCalibrationError(
            f"the target's pose could be found in {len(index)} left image(s); at least 3 are needed"
        )
    cands = hand_eye_candidates(T_base_tool0[list(index)], T_ct)
    best = min(cands, key=lambda c: c.spread_m + 0.1 * c.spread_rad)
    if not np.isfinite(best.spread_m):
        raise DegenerateCalibrationError("every OpenCV hand-eye method failed on these views")
    return InitialEstimate(best=best, candidates=cands, T_camera_target=T_ct, pnp_views=index)
