"""Applying the thermal model at one pose.

1. The measurement transform: a hole measured in the camera frame is carried
   into the part frame through the compensated forward kinematics at the
   temperatures of the moment, ``T_part_cam = T_cell_part^-1 T_cell_base
   T_base_tool0(q, T) T_tool0_tcp T_tcp_cam``.
2. The command: the joint vector that puts the TCP at the nominal pose (the
   pose the planner computed with the nominal model) under the current
   temperatures. Damped Newton steps on the compensated D-H table, starting
   from the nominal joint vector, with the geometric Jacobian.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial.transform import Rotation

from robots.dh import DHTable, fk_dh, fk_dh_frames
from robots.thermal.model import ThermalModel
from robots.transforms import invert

Array = NDArray[np.float64]


def compensated_T_base_tcp(model: ThermalModel, q: ArrayLike, temps_degC: ArrayLike) -> Array:
    """Compensated ``T_base_tcp`` (..., 4, 4) at joints ``q`` (rad) and sensor readings (degC)."""
    return model.fk(q, temps_degC) @ model.T_tool0_tcp


def compensated_T_cell_tcp(
    model: ThermalModel,
    T_cell_base: ArrayLike,
    T_tool0_tcp: ArrayLike,
    q: ArrayLike,
    temps_degC: ArrayLike,
) -> Array:
    """Compensated ``T_cell_tcp`` (..., 4, 4): ``T_cell_base @ model.fk(q, T) @ T_tool0_tcp``.

    The one place where the compensated TCP pose in the cell is formed. The base pose and the
    tool are given explicitly (the cell's, or the model's own), so a caller never mixes a
    model's tool with another cell's base. ``q`` in rad, readings in degC.
    """
    T_cb = np.asarray(T_cell_base, float)
    T_tt = np.asarray(T_tool0_tcp, float)
    return T_cb @ model.fk(q, temps_degC) @ T_tt


def T_part_camera(
    model: ThermalModel,
    q: ArrayLike,
    temps_degC: ArrayLike,
    T_cell_part: ArrayLike,
    T_tcp_cam: ArrayLike | None = None,
) -> Array:
    """``T_part_cam`` (4x4): camera-frame coordinates into the part frame at this pose and moment.

    ``T_cell_part`` is the part pose in the cell; ``T_tcp_cam`` the camera frame in the
    TCP frame (identity when the measurement is expressed in the TCP frame).
    """
    T_tcp_cam = np.eye(4) if T_tcp_cam is None else np.asarray(T_tcp_cam, float)
    T_cell_tcp = compensated_T_cell_tcp(model, model.T_cell_base, model.T_tool0_tcp, q, temps_degC)
    return invert(T_cell_part) @ T_cell_tcp @ T_tcp_cam


def camera_to_part(
    T_part_cam: ArrayLike, points_cam_m: ArrayLike, axes_cam: ArrayLike | None = None
) -> tuple[Array, Array | None]:
    """Points (N, 3) m and optional unit axes (N, 3) from the camera frame into the part frame."""
    T = np.asarray(T_part_cam, float)
    p = np.asarray(points_cam_m, float) @ T[:3, :3].T + T[:3, 3]
    axes = None if axes_cam is None else np.asarray(axes_cam, float) @ T[:3, :3].T
    return p, axes


@dataclass(frozen=True)
class CommandOptions:
    """Settings of the iterative pose solve.

    Attributes:
        position_tol_m: stop when the TCP position error is below this (m).
        rotation_tol_rad: and the orientation error is below this (rad).
        max_iterations: Newton steps at most.
        damping: damping of the least-squares step (m and rad scale).
        position_only: match only the TCP position (orientation free).
    """

    position_tol_m: float = 1e-10
    rotation_tol_rad: float = 1e-10
    max_iterations: int = 30
    damping: float = 1e-6
    position_only: bool = False


@dataclass(frozen=True)
class CommandResult:
    """Joints (rad) putting the TCP at a goal pose; ``status`` "converged" or "not converged"."""

    status: str
    q_rad: Array
    iterations: int
    position_error_m: float
    rotation_error_rad: float
    timings: dict[str, float] = field(default_factory=dict)

    @property
    def ok(self) -> bool:
        return self.status == "converged"


def _pose_error(T_goal: Array, T: Array) -> tuple[Array, Array]:
    e_p = T_goal[:3, 3] - T[:3, 3]
    e_w = Rotation.from_matrix(T_goal[:3, :3] @ T[:3, :3].T).as_rotvec()
    return e_p, e_w


def _jacobian(table: DHTable, q: Array, T_tool0_tcp: Array) -> tuple[Array, Array]:
    """Geometric Jacobian (6, 6) in the base frame at the TCP, and ``T_base_tcp``."""
    frames = fk_dh_frames(table, q)
    T_base_tcp = frames[6] @ T_tool0_tcp
    z = frames[:6, :3, 2] * np.asarray(table.joint_sign)[:, None]  # each joint's own axis
    o = frames[:6, :3, 3]
    Jv = np.cross(z, T_base_tcp[:3, 3] - o).T
    return np.vstack((Jv, z.T)), T_base_tcp


def solve_tcp(
    table: DHTable,
    T_base_tcp_goal: ArrayLike,
    q_seed: ArrayLike,
    T_tool0_tcp: ArrayLike,
    options: CommandOptions | None = None,
) -> CommandResult:
    """Joints that put ``fk_dh(table, q) @ T_tool0_tcp`` at ``T_base_tcp_goal``, from ``q_seed``."""
    options = options or CommandOptions()
    t0 = time.perf_counter()
    T_goal = np.asarray(T_base_tcp_goal, float)
    T_tt = np.asarray(T_tool0_tcp, float)
    q = np.asarray(q_seed, float).copy()
    rows = slice(0, 3) if options.position_only else slice(0, 6)
    it = 0
    while True:
        J, T = _jacobian(table, q, T_tt)
        e_p, e_w = _pose_error(T_goal, T)
        ep, ew = float(np.linalg.norm(e_p)), float(np.linalg.norm(e_w))
        done = ep <= options.position_tol_m and (
            options.position_only or ew <= options.rotation_tol_rad
        )
        if done or it >= options.max_iterations:
            break
        Jr = J[rows]
        e = np.concatenate((e_p, e_w))[rows]
        A = Jr @ Jr.T + options.damping**2 * np.eye(Jr.shape[0])
        q = q + Jr.T @ np.linalg.solve(A, e)
        it += 1
    return CommandResult(
        status="converged" if done else "not converged",
        q_rad=q,
        iterations=it,
        position_error_m=ep,
        rotation_error_rad=0.0 if options.position_only else ew,
        timings={"solve_s": time.perf_counter() - t0},
    )


def command(
    model: ThermalModel,
    q_nominal: ArrayLike,
    temps_degC: ArrayLike,
    options: CommandOptions | None = None,
) -> CommandResult:
    """Joints putting the TCP at its nominal pose ``fk_nominal(q_nominal)`` at these temperatures.

    The nominal pose is what the planner computed on the nominal table; the result
    drives the compensated (warm) arm there. Starts from ``q_nominal``.
    """
    q_nominal = np.asarray(q_nominal, float)
    T_goal = fk_dh(model.table, q_nominal) @ model.T_tool0_tcp
    warm = model.table_at(np.asarray(temps_degC, float))
    return solve_tcp(warm, T_goal, q_nominal, model.T_tool0_tcp, options)
