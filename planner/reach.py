"""Reachability of holes: how many IK branches of a hole's nominal viewpoint are usable.

The nominal viewpoint of a hole puts the TCP on the hole's axis at the tool's
standoff, looking into the hole (TCP z = -normal), with the roll about the
view axis free. This module samples the roll and counts, over all samples,
the IK solutions within limits and those also free of collision. A hole with
none free along its axis is tried again on the planner's fallback tilt cone
(``planner.Options.fallback_tilt_deg``), as ``holecell plan`` does.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from planner import Options
from planner.viewpoints import view_directions
from robots import Arm
from robots.transforms import frame_from_z_axis


@dataclass(frozen=True)
class HoleReach:
    """Reach summary of one hole (or reference target)."""

    id: str
    n_solutions: int  # IK solutions within limits, over every sampled roll
    n_free: int  # of those, free of collision
    rolls_free: int  # sampled rolls with at least one free solution
    n_rolls: int
    reason: str | None  # why none is usable, when none is
    tilt_deg: float = 0.0  # 0: along the axis; else the fallback cone's half-angle used

    @property
    def reachable(self) -> bool:
        """True when at least one collision-free solution exists."""
        return self.n_free > 0


def viewpoint(
    position_m: np.ndarray, normal: np.ndarray, standoff_m: float, roll_rad: float
) -> np.ndarray:
    """``T_cell_tcp`` viewing a hole at ``position_m`` (cell frame) along ``-normal``."""
    return frame_from_z_axis(position_m + standoff_m * normal, -normal, roll_rad)


def hole_reach(
    arm: Arm,
    hole_id: str,
    position_m: np.ndarray,
    normal: np.ndarray,
    standoff_m: float,
    roll_step_rad: float,
    fallback_tilt_deg: float = Options.fallback_tilt_deg,
) -> HoleReach:
    """Count usable IK branches of a hole's viewpoint over the sampled rolls; when none is
    free along the axis, over the fallback tilt cone's directions instead."""
    axial = _reach(arm, hole_id, position_m, [-np.asarray(normal)], standoff_m, roll_step_rad, 0)
    if axial.reachable or fallback_tilt_deg <= 0:
        return axial
    dirs = view_directions(normal, fallback_tilt_deg, Options.tilt_azimuths)[1:]
    tilted = _reach(arm, hole_id, position_m, dirs, standoff_m, roll_step_rad, fallback_tilt_deg)
    return tilted if tilted.reachable else axial


def _reach(
    arm: Arm,
    hole_id: str,
    position_m: np.ndarray,
    view_dirs: list[np.ndarray] | np.ndarray,
    standoff_m: float,
    roll_step_rad: float,
    tilt_deg: float,
) -> HoleReach:
    rolls = np.arange(0.0, 2.0 * np.pi - 1e-9, roll_step_rad)
    n_sol = n_free = rolls_free = 0
    reasons: set[str] = set()
    for roll in rolls:
        free_here = 0
        for z in view_dirs:
            result = arm.ik(viewpoint(position_m, -np.asarray(z), standoff_m, roll))
            if not result.ok:
                reasons.add(result.reason or "no solution")
                continue
            free = sum(not arm.in_collision(q) for q in result.solutions)
            n_sol += len(result.solutions)
            free_here += free
        n_free += free_here
        rolls_free += free_here > 0
    reason = None
    if n_free == 0:
        reason = "in collision from every viewpoint" if n_sol else ", ".join(sorted(reasons))
    return HoleReach(hole_id, n_sol, n_free, rolls_free, len(rolls), reason, tilt_deg)
