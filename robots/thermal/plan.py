"""Viewing poses for the reference targets: the pose plan of a thermal identification.

Each target is seen from several views: the camera axis (TCP z) points into the
target against its normal, tilted by ``tilt`` towards an azimuth measured from
the direction of the target as seen from the robot base, rolled about the axis,
with the target at ``standoff_m`` along TCP z. Each view is solved by the
closed-form IK (:func:`robots.ik.solve_ik`); the solution nearest a rest
configuration (arm in front, elbow up) is kept. docs/thermal.md says which
plans identify which terms; three views per target with poses that differ in
J1-J3 are the recommended minimum.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robots.dh import DHTable
from robots.ik import solve_ik
from robots.thermal.errors import ThermalDataError
from robots.transforms import frame_from_z_axis, invert

Array = NDArray[np.float64]


@dataclass(frozen=True)
class ViewOptions:
    """The views of every target: tilt from the normal, azimuth and roll (rad), paired by index."""

    tilts_rad: tuple[float, ...] = (0.0, 0.45, 0.45)
    azimuths_rad: tuple[float, ...] = (0.0, 0.0, 2.2)
    rolls_rad: tuple[float, ...] = (0.0, 1.2, -0.8)


@dataclass(frozen=True)
class ViewPlan:
    """``poses``: (target id, joints rad) per reachable view; ``skipped``: (id, view, reason)."""

    poses: list[tuple[str, Array]]
    skipped: list[tuple[str, int, str]] = field(default_factory=list)


def view_pose(
    target_base_m: ArrayLike,
    normal_base: ArrayLike,
    tilt: float,
    azimuth: float,
    roll: float,
    standoff_m: float,
) -> Array:
    """``T_base_tcp`` viewing a target (base frame) with the target at ``standoff_m`` on TCP z."""
    p = np.asarray(target_base_m, float)
    n = np.asarray(normal_base, float)
    n = n / np.linalg.norm(n)
    e1 = np.array([p[0], p[1], 0.0])
    e1 = e1 - n * (e1 @ n)
    if np.linalg.norm(e1) < 1e-9:
        e1 = np.array([1.0, 0.0, 0.0]) - n * n[0]
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(n, e1)
    z = -np.cos(tilt) * n + np.sin(tilt) * (np.cos(azimuth) * e1 + np.sin(azimuth) * e2)
    return frame_from_z_axis(p - standoff_m * z, z, roll)


def view_plan(
    table: DHTable,
    lower: ArrayLike,
    upper: ArrayLike,
    T_cell_base: ArrayLike,
    T_tool0_tcp: ArrayLike,
    targets: Mapping[str, tuple[ArrayLike, ArrayLike]],
    standoff_m: float,
    options: ViewOptions | None = None,
    accept: Callable[[Array], bool] | None = None,
) -> ViewPlan:
    """Joint vectors viewing every target (cell-frame ``(position m, unit normal)`` by id).

    ``accept(q)`` may veto a solution (e.g. a collision check); vetoed or unreachable
    views are listed in ``skipped``. Raises :class:`ThermalDataError` when no view works.
    """
    options = options or ViewOptions()
    T_base_cell = invert(np.asarray(T_cell_base, float))
    T_tcp_tool0 = invert(np.asarray(T_tool0_tcp, float))
    lo, hi = np.asarray(lower, float), np.asarray(upper, float)
    poses: list[tuple[str, Array]] = []
    skipped: list[tuple[str, int, str]] = []
    views = list(zip(options.tilts_rad, options.azimuths_rad, options.rolls_rad, strict=True))
    for tid, (pos, normal) in targets.items():
        p = T_base_cell[:3, :3] @ np.asarray(pos, float) + T_base_cell[:3, 3]
        n = T_base_cell[:3, :3] @ np.asarray(normal, float)
        rest = np.array([np.arctan2(p[1], p[0]), 0.3, 0.0, 0.0, 1.0, 0.0])
        for k, (tilt, az, roll) in enumerate(views):
            T = view_pose(p, n, tilt, az, roll, standoff_m) @ T_tcp_tool0
            ik = solve_ik(table, T, lo, hi)
            sols = ik.solutions
            if accept is not None and len(sols):
                sols = np.array([q for q in sols if accept(q)]).reshape(-1, 6)
            if not len(sols):
                skipped.append((tid, k, ik.reason or "every solution vetoed (collision)"))
                continue
            poses.append((tid, sols[np.argmin(np.abs(sols - rest).sum(axis=1))]))
    if not poses:
        reasons = "; ".join(f"{t} view {k}: {r}" for t, k, r in skipped)
        raise ThermalDataError("view plan", f"no reference target view is reachable ({reasons})")
    return ViewPlan(poses, skipped)
