"""Sampling a timeline of motions and dwells at the controller period, and checking limits."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from planner.timing import JointLimits, TimedMotion


@dataclass(frozen=True)
class Dwell:
    """The arm rests at ``q`` (rad) for ``duration`` (s)."""

    q: NDArray[np.float64]
    duration: float

    def positions(self, times: NDArray[np.float64]) -> NDArray[np.float64]:
        """``q`` repeated once per time."""
        return np.repeat(
            np.asarray(self.q, dtype=float)[None, :], len(np.atleast_1d(times)), axis=0
        )


def sample_timeline(items: Sequence[TimedMotion | Dwell], dt: float) -> NDArray[np.float64]:
    """Joint positions (rad) every ``dt`` s from 0 to the end of the last item (end included).

    Items follow each other in time; the last row is the final rest position,
    sampled at ``ceil(total / dt) * dt``.
    """
    durations = np.array([it.duration for it in items], dtype=float)
    starts = np.concatenate([[0.0], np.cumsum(durations)])
    total = float(starts[-1])
    n = int(np.ceil(total / dt - 1e-9))
    times = np.arange(n + 1) * dt
    which = np.clip(np.searchsorted(starts, times, side="right") - 1, 0, len(items) - 1)
    out = np.empty((n + 1, len(_end(items[-1]))))
    for k, item in enumerate(items):
        mask = which == k
        if mask.any():
            out[mask] = item.positions(np.minimum(times[mask] - starts[k], item.duration))
    return out


def _end(item: TimedMotion | Dwell) -> NDArray[np.float64]:
    return np.asarray(item.q if isinstance(item, Dwell) else item.waypoints[-1], dtype=float)


@dataclass(frozen=True)
class LimitReport:
    """Largest finite-difference velocity, acceleration and jerk relative to the limits.

    A ratio of 1 means at the limit; ``position_ok`` says every sample is within limits.
    """

    velocity_ratio: float
    acceleration_ratio: float
    jerk_ratio: float
    position_ok: bool

    def within(self, tolerance: float = 1e-6) -> bool:
        """True when no ratio exceeds ``1 + tolerance`` and positions are within limits."""
        worst = max(self.velocity_ratio, self.acceleration_ratio, self.jerk_ratio)
        return self.position_ok and worst <= 1.0 + tolerance


def finite_difference_limits(q: NDArray[np.float64], dt: float, limits: JointLimits) -> LimitReport:
    """Check a sampled trajectory (rows every ``dt`` s) by finite differences.

    For a motion with bounded third derivative, the k-th difference divided by
    ``dt**k`` is a weighted mean of the k-th derivative, so it stays within the
    limit up to rounding.
    """
    v = np.diff(q, axis=0) / dt
    a = np.diff(q, n=2, axis=0) / dt**2
    j = np.diff(q, n=3, axis=0) / dt**3

    def ratio(x: NDArray[np.float64], lim: NDArray[np.float64]) -> float:
        return float(np.max(np.abs(x) / lim)) if len(x) else 0.0

    pos_ok = bool(np.all(q >= limits.lower - 1e-9) and np.all(q <= limits.upper + 1e-9))
    return LimitReport(
        ratio(v, limits.velocity), ratio(a, limits.acceleration), ratio(j, limits.jerk), pos_ok
    )
