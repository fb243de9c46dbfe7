"""The observation model of the cell calibration: predicted corners and their Jacobian.

A corner ``p`` of the target (plate frame, m) seen in view ``v``::

    X_left  = inv(T_base_tool0(q_v; delta) @ T_tool0_camera) @ T_base_target @ p
    X_right = inv(T_left_right) @ X_left
    pixel   = OpenCV projection with the camera's K and distortion (cv2.projectPoints)

Unknowns (:class:`State`): ``T_tool0_camera``, ``T_base_target``, ``T_left_right`` (stereo) and
the D-H error vector ``delta`` (:mod:`robots.calibration`). A pose is perturbed as
``R = exp([w]) R0, t = t0 + v``: six columns ``(vx, vy, vz)`` m and ``(wx, wy, wz)`` rad, the
rotation vector in the parent frame (``base_link`` for the target, ``tool0`` for the camera,
``left`` for the right camera). Jacobian columns, in this order: hand-eye (6), target (6),
stereo extrinsics (6, stereo heads only), the 24 D-H terms (views with joints only).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import cv2
import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from cell.calibration.estimate.observations import CalibrationObservations, Intrinsics
from robots.calibration import dh_error_twists, fk_with_errors, term_names
from robots.dh import DHTable
from robots.transforms import skew

Array = NDArray[np.float64]

POSE_COLUMNS = ("x_m", "y_m", "z_m", "rx_rad", "ry_rad", "rz_rad")
#: the lens corrections of one camera: added to its ``K`` (px) and its distortion (OpenCV order)
INTRINSIC_COLUMNS = ("fx_px", "fy_px", "cx_px", "cy_px", "k1", "k2", "p1", "p2", "k3")
N_INTRINSIC = len(INTRINSIC_COLUMNS)


@dataclass(frozen=True, eq=False)
class State:
    """Current values of the unknowns (4x4 poses in metres, ``delta`` (24,))."""

    T_tool0_camera: Array
    T_base_target: Array
    T_left_right: Array | None
    delta: Array
    intrinsics: Array | None = None  # corrections (px) fx, fy, cx, cy of left (and right)


def column_names(stereo: bool, kinematic: bool, intrinsics: bool = False) -> tuple[str, ...]:
    """Names of the Jacobian's columns (see the module docstring); ``intrinsics``: the
    corrections of each camera's fx, fy, cx, cy (px) last."""
    names = [f"T_tool0_camera.{c}" for c in POSE_COLUMNS]
    names += [f"T_base_target.{c}" for c in POSE_COLUMNS]
    if stereo:
        names += [f"T_left_right.{c}" for c in POSE_COLUMNS]
    if kinematic:
        names += [f"dh.{n}" for n in term_names()]
    if intrinsics:
        for side in ("left", "right") if stereo else ("left",):
            names += [f"intrinsics.{side}.{c}" for c in INTRINSIC_COLUMNS]
    return tuple(names)


def intrinsic_names(stereo: bool) -> tuple[str, ...]:
    """The intrinsic correction columns of a head (stereo: left then right)."""
    return tuple(c for c in column_names(stereo, False, True) if c.startswith("intrinsics."))


def corrected(cam: Intrinsics, d: Array) -> Intrinsics:
    """``cam`` with ``d`` = (fx, fy, cx, cy) corrections (px) added to its ``K``."""
    K = cam.K.copy()
    K[0, 0] += d[0]
    K[1, 1] += d[1]
    K[0, 2] += d[2]
    K[1, 2] += d[3]
    dist = np.zeros(max(5, len(cam.dist)))
    dist[: len(cam.dist)] = cam.dist
    dist[:5] += d[4:9]
    return Intrinsics(K, dist, cam.image_size)


def perturb_pose(T0: Array, x: Array) -> Array:
    """``T0`` moved by ``x = (v (m), w (rad))``: ``R = exp([w]) R0``, ``t = t0 + v``."""
    T = np.eye(4)
    T[:3, :3] = Rotation.from_rotvec(x[3:6]).as_matrix() @ T0[:3, :3]
    T[:3, 3] = T0[:3, 3] + x[:3]
    return T


def step_state(state: State, x: Array, columns: tuple[str, ...]) -> State:
    """The state moved by ``x`` over the named columns (the others unchanged)."""
    full = dict(zip(columns, x, strict=True))

    def block(prefix: str) -> Array:
        return np.array([full.get(f"{prefix}.{c}", 0.0) for c in POSE_COLUMNS])

    delta = state.delta + np.array([full.get(f"dh.{n}", 0.0) for n in term_names()])
    intr = state.intrinsics
    if intr is not None:
        names = intrinsic_names(len(intr) == 2 * N_INTRINSIC)
        intr = intr + np.array([full.get(n, 0.0) for n in names])
    return replace(
        state,
        T_tool0_camera=perturb_pose(state.T_tool0_camera, block("T_tool0_camera")),
        T_base_target=perturb_pose(state.T_base_target, block("T_base_target")),
        T_left_right=(
            None
            if state.T_left_right is None
            else perturb_pose(state.T_left_right, block("T_left_right"))
        ),
        delta=delta,
        intrinsics=intr,
    )


def flange_poses(obs: CalibrationObservations, dh: DHTable | None, delta: Array) -> Array:
    """``T_base_tool0`` (V, 4, 4) of every view: D-H with errors, or the given flange poses."""
    if dh is not None and obs.has_joints:
        return fk_with_errors(dh, delta, obs.joints())
    return np.array([np.asarray(v.T_base_tool0, float) for v in obs.views])


def _project(X: Array, cam: Intrinsics, jac: bool) -> tuple[Array, Array | None, Array | None]:
    """Pixels (N, 2) of camera points (N, 3), d pixel / d X (N, 2, 3) and d pixel / d (fx, fy,
    cx, cy) (2N, 4)."""
    px, J = cv2.projectPoints(X.reshape(-1, 1, 3), np.zeros(3), np.zeros(3), cam.K, cam.dist)
    if not jac:
        return px.reshape(-1, 2), None, None
    return px.reshape(-1, 2), J[:, 3:6].reshape(-1, 2, 3), J[:, 6:15]


@dataclass(frozen=True, eq=False)
class Prediction:
    """Residuals (predicted - observed, px) of the seen views, and the Jacobian if asked.

    ``residuals`` stacks, per camera (left then right), the seen views' corners (x, y);
    ``view_index`` (rows/2,) and ``camera`` ("left"/"right" per corner) tell whose they are.
    ``flange_jacobian`` (rows, 6), when asked: d residual / d (flange position error (m),
    flange rotation error about the flange's origin (rad)), both in ``base_link``, of the
    row's own view (an error of the arm's pose at that view alone).
    """

    residuals: Array
    jacobian: Array | None
    view_index: NDArray[np.int64]
    camera: NDArray[np.str_]
    flange_jacobian: Array | None = None


def predict(
    obs: CalibrationObservations,
    dh: DHTable | None,
    state: State,
    jac: bool = True,
    flange_jac: bool = False,
) -> Prediction:
    """Residuals and Jacobian (rows: corners x/y; columns: :func:`column_names`); with
    ``flange_jac`` also the Jacobian of each row against its view's flange pose error."""
    kinematic = dh is not None and obs.has_joints
    stereo = obs.cameras.stereo and state.T_left_right is not None
    cols = column_names(stereo, kinematic)  # the geometric columns; the intrinsics follow
    n_intr = 0 if state.intrinsics is None else N_INTRINSIC * (2 if stereo else 1)
    p = obs.target.object_points()  # (M, 3)
    T_bt = flange_poses(obs, dh, state.delta)  # (V, 4, 4)
    R_bt, t_bt = T_bt[:, :3, :3], T_bt[:, :3, 3]
    R_X, t_X = state.T_tool0_camera[:3, :3], state.T_tool0_camera[:3, 3]
    R_Y, t_Y = state.T_base_target[:3, :3], state.T_base_target[:3, 3]
    Rp = p @ R_Y.T  # (M, 3) rotated corners
    P_b = Rp + t_Y
    P_t0 = np.einsum("vji,vmj->vmi", R_bt, P_b[None] - t_bt[:, None])  # R_bt^T (P_b - t_bt)
    y = P_t0 - t_X
    X_l = y @ R_X  # R_X^T y, (V, M, 3)
    V, M = X_l.shape[:2]
    D = None
    n_cols = len(cols) + (6 if flange_jac else 0)
    if jac or flange_jac:
        D = np.zeros((V, M, 3, n_cols))
        A = np.einsum("ji,vkj->vik", R_X, R_bt)  # R_X^T R_bt^T, (V, 3, 3)
        D[..., 0:3] = -R_X.T
        D[..., 3:6] = np.einsum("ji,vmjk->vmik", R_X, skew(y))
        D[..., 6:9] = A[:, None]
        D[..., 9:12] = -np.einsum("vij,mjk->vmik", A, skew(Rp))
        if kinematic:
            tw = dh_error_twists(dh, state.delta, obs.joints())  # (V, 24, 6)
            k0 = 18 if stereo else 12
            # dX_l = -A (v_s + w_s x P_b)
            moved = tw[:, None, :, :3] + np.cross(tw[:, None, :, 3:], P_b[None, :, None, :])
            D[..., k0 : k0 + 24] = -np.einsum("vij,vmkj->vmik", A, moved)
        if flange_jac:  # dX_l = -A (dp + dtheta x (P_b - p_flange))
            arm = P_b[None] - t_bt[:, None]  # (V, M, 3)
            D[..., -6:-3] = -A[:, None]
            D[..., -3:] = np.einsum("vij,vmjk->vmik", A, skew(arm))
    rows_r, rows_J, views, cams = [], [], [], []
    sides = [("left", obs.cameras.left)]
    if stereo:
        sides.append(("right", obs.cameras.right))
    if state.intrinsics is not None:
        sides = [(side, corrected(cam, state.intrinsics[N_INTRINSIC * i : N_INTRINSIC * (i + 1)]))
                 for i, (side, cam) in enumerate(sides)]  # fmt: skip
    for i_side, (side, cam) in enumerate(sides):
        corners, seen = obs.corners(side)
        if not seen.any():
            continue
        Xs = X_l[seen]
        Ds = D[seen] if D is not None else None
        if side == "right":
            R_L, t_L = state.T_left_right[:3, :3], state.T_left_right[:3, 3]
            z = Xs - t_L
            if Ds is not None:
                Ds = np.einsum("ji,vmjk->vmik", R_L, Ds)
                Ds[..., 12:15] = -R_L.T
                Ds[..., 15:18] = np.einsum("ji,vmjk->vmik", R_L, skew(z))
            Xs = z @ R_L
        px, Jp, Jk = _project(Xs.reshape(-1, 3), cam, Ds is not None)
        rows_r.append((px - corners[seen].reshape(-1, 2)).reshape(-1))
        if Ds is not None:
            geo = np.einsum("nij,njk->nik", Jp, Ds.reshape(-1, 3, n_cols)).reshape(-1, n_cols)
            intr = np.zeros((len(geo), n_intr))
            if n_intr:
                intr[:, N_INTRINSIC * i_side : N_INTRINSIC * (i_side + 1)] = Jk
            rows_J.append(np.hstack([geo[:, : len(cols)], intr, geo[:, len(cols) :]]))
        views.append(np.repeat(np.flatnonzero(seen), M))
        cams.append(np.full(int(seen.sum()) * M, side))
    J_all = np.concatenate(rows_J) if rows_J else None
    k = len(cols) + n_intr
    return Prediction(
        residuals=np.concatenate(rows_r),
        jacobian=J_all[:, :k] if jac else None,
        view_index=np.concatenate(views),
        camera=np.concatenate(cams),
        flange_jacobian=J_all[:, k:] if flange_jac else None,
    )
