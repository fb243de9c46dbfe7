"""Reachability of holes: how many IK branches of a hole's nominal viewpoint are usable.

The nominal viewpoint of a hole puts the TCP on the hole's axis at the tool's
standoff, looking into the hole (TCP z = -normal), with the roll about the
view axis free. This module samples the roll and counts, over all samples,
the IK solutions within limits and those also free of collision.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

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
) -> HoleReach:
    """Count usable IK branches of a hole's viewpoint over the sampled rolls."""
    rolls = np.arange(0.0, 2.0 * np.pi - 1e-9, roll_step_rad)
    n_sol = n_free = rolls_free = 0
    reasons: set[str] = set()
    for roll in rolls:
        result = arm.ik(viewpoint(position_m, normal, standoff_m, roll))
        if not result.ok:
            reasons.add(result.reason or "no solution")
            continue
        free = sum(not arm.in_collision(q) for q in result.solutions)
        n_sol += len(result.solutions)
        n_free += free
        rolls_free += free > 0
    reason = None
    if n_free == 0:
        reason = "in collision from every viewpoint" if n_sol else ", ".join(sorted(reasons))
    return HoleReach(hole_id, n_sol, n_free, rolls_free, len(rolls), reason)
