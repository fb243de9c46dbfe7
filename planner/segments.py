"""Collision-free, timed segments between configurations, planned once and cached."""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from planner.paths import MotionChecker, SegmentPath, SegmentPlanner, seed_ompl
from planner.timing import JointLimits, TimedMotion, rest_to_rest, through_waypoints, time_path


@dataclass(frozen=True)
class Segment:
    """A path between two stops and its jerk-limited timing."""

    path: SegmentPath
    motion: TimedMotion


class SegmentCache:
    """Plans (straight or OMPL) and times segments; each pair of configurations once.

    ``pass_through`` flies through OMPL waypoints where the sampled motion is free
    (:func:`planner.timing.time_path`); otherwise every waypoint is a stop.
    """

    def __init__(
        self,
        checker: MotionChecker,
        limits: JointLimits,
        seed: int,
        segment_time_s: float,
        dt: float,
        pass_through: bool,
    ) -> None:
        seed_ompl(seed)
        self.checker = checker
        self.limits = limits
        self.planner = SegmentPlanner(checker, limits.lower, limits.upper)
        self.segment_time_s = segment_time_s
        self.dt = dt
        self.pass_through = pass_through
        self.cache: dict[bytes, Segment] = {}
        self.path_time_s = 0.0
        self.timing_time_s = 0.0

    def _time(self, path: SegmentPath) -> TimedMotion:
        if not path.planned:
            return rest_to_rest(path.waypoints[0], path.waypoints[-1], self.limits)
        if self.pass_through:
            return time_path(path.waypoints, self.limits, self.checker.polyline_free, self.dt)
        stops = np.ones(len(path.waypoints), dtype=bool)
        return through_waypoints(path.waypoints, self.limits, stops)

    def get(
        self,
        q_a: NDArray[np.float64],
        q_b: NDArray[np.float64],
        names: tuple[str, str],
        via: NDArray[np.float64] | None = None,
        straight_free: bool = False,
    ) -> Segment:
        """The segment ``q_a`` to ``q_b`` (rad); :class:`SegmentPlanningError` if unsolvable.

        ``via``: intermediate configurations of a roadmap detour, tried before OMPL.
        ``straight_free``: the straight motion is known free at the set resolution (a batch
        check of the same samples, :class:`planner.edge_check.BatchEdgeChecker`): not
        checked again.
        """

        key = np.concatenate([q_a, q_b]).tobytes()
        if key not in self.cache:
            t = time.perf_counter()
            path = self.planner.plan(q_a, q_b, self.segment_time_s, names, via, straight_free)
            self.path_time_s += time.perf_counter() - t
            t = time.perf_counter()
            self.cache[key] = Segment(path, self._time(path))
            self.timing_time_s += time.perf_counter() - t
        return self.cache[key]
