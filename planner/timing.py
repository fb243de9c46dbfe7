"""Jerk-limited time parameterisation with ruckig.

Only single-target ruckig calculations are used, chained one after the other
(ruckig's intermediate-waypoint input is never set: the free package would send
the waypoints to a remote service). A straight joint-space segment is timed rest-to-rest
with phase synchronisation, which keeps it on the straight line. A multi-point
path (from OMPL) is timed through its waypoints with non-zero velocity where
the caller's collision check of the sampled motion allows, else with a stop.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
import ruckig
from numpy.typing import ArrayLike, NDArray

from planner.errors import TimingError

#: fraction of a joint's velocity limit used at most when flying through a waypoint
PASS_VELOCITY_FRACTION = 0.9


@dataclass(frozen=True)
class JointLimits:
    """Joint limits of the arm: positions (rad), velocity (rad/s), acceleration, jerk."""

    lower: NDArray[np.float64]
    upper: NDArray[np.float64]
    velocity: NDArray[np.float64]
    acceleration: NDArray[np.float64]
    jerk: NDArray[np.float64]

    @classmethod
    def from_arm(cls, arm: object) -> JointLimits:
        """Read the (already scaled) limits of a ``robots.Arm``."""
        return cls(
            lower=np.asarray(arm.lower, dtype=np.float64),  # type: ignore[attr-defined]
            upper=np.asarray(arm.upper, dtype=np.float64),  # type: ignore[attr-defined]
            velocity=np.asarray(arm.velocity_limit, dtype=np.float64),  # type: ignore[attr-defined]
            acceleration=np.asarray(arm.acceleration_limit, dtype=np.float64),  # type: ignore[attr-defined]
            jerk=np.asarray(arm.jerk_limit, dtype=np.float64),  # type: ignore[attr-defined]
        )

    @property
    def dof(self) -> int:
        """Number of joints."""
        return int(self.velocity.shape[0])


class TimedMotion:
    """A motion made of chained ruckig trajectories (each starting where the last ended).

    ``waypoints`` are the joint positions (rad) at the piece boundaries, ``stops`` marks
    where the motion comes to rest (always at both ends).
    """

    def __init__(
        self,
        pieces: Sequence[ruckig.Trajectory],
        waypoints: NDArray[np.float64],
        stops: NDArray[np.bool_],
    ) -> None:
        self.pieces = list(pieces)
        self.waypoints = waypoints
        self.stops = stops
        durations = np.array([p.duration for p in self.pieces], dtype=float)
        self.piece_starts = np.concatenate([[0.0], np.cumsum(durations)])

    @property
    def duration(self) -> float:
        """Total duration (s)."""
        return float(self.piece_starts[-1])

    def state(
        self, t: float
    ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
        """Position (rad), velocity (rad/s) and acceleration (rad/s^2) at time ``t`` (s)."""
        if not self.pieces:
            zeros = np.zeros(self.waypoints.shape[1])
            return self.waypoints[0].copy(), zeros, zeros.copy()
        t = min(max(t, 0.0), self.duration)
        k = int(np.searchsorted(self.piece_starts, t, side="right")) - 1
        k = min(max(k, 0), len(self.pieces) - 1)
        p, v, a = self.pieces[k].at_time(t - self.piece_starts[k])
        return np.asarray(p), np.asarray(v), np.asarray(a)

    @property
    def q(self) -> NDArray[np.float64]:
        """Final joint position (rad)."""
        return self.waypoints[-1]

    def positions(self, times: ArrayLike) -> NDArray[np.float64]:
        """Joint positions (rad), one row per time in ``times`` (s from the motion's start)."""
        t = np.atleast_1d(np.asarray(times, dtype=float))
        if not self.pieces:
            return np.repeat(self.waypoints[:1], len(t), axis=0)
        # :meth:`state`'s clamping and piece lookup for every time at once (the same numbers)
        t = np.minimum(np.maximum(t, 0.0), self.duration)
        ks = np.searchsorted(self.piece_starts, t, side="right") - 1
        ks = np.minimum(np.maximum(ks, 0), len(self.pieces) - 1)
        local = (t - self.piece_starts[ks]).tolist()
        at = [p.at_time for p in self.pieces]
        return np.array([at[k](x)[0] for k, x in zip(ks.tolist(), local, strict=True)])

    def piece_positions(self, k: int, dt: float) -> NDArray[np.float64]:
        """Positions of piece ``k`` sampled every ``dt`` s, both ends included."""
        piece = self.pieces[k]
        n = max(int(np.ceil(piece.duration / dt)), 1)
        times = np.linspace(0.0, piece.duration, n + 1)
        return np.array([piece.at_time(float(t))[0] for t in times])


def _calculate(
    otg: ruckig.Ruckig,
    inp: ruckig.InputParameter,
    what: str,
) -> ruckig.Trajectory:
    traj = ruckig.Trajectory(inp.degrees_of_freedom)
    result = otg.calculate(inp, traj)
    if result not in (ruckig.Result.Working, ruckig.Result.Finished):
        raise TimingError(what, str(result))
    return traj


def _input(limits: JointLimits) -> ruckig.InputParameter:
    inp = ruckig.InputParameter(limits.dof)
    inp.max_velocity = limits.velocity
    inp.max_acceleration = limits.acceleration
    inp.max_jerk = limits.jerk
    return inp


def rest_to_rest(q_from: ArrayLike, q_to: ArrayLike, limits: JointLimits) -> TimedMotion:
    """Time-optimal, phase-synchronised rest-to-rest motion: stays on the straight joint line."""
    return through_waypoints(np.array([q_from, q_to], dtype=float), limits)


def pass_velocities(waypoints: NDArray[np.float64], limits: JointLimits) -> NDArray[np.float64]:
    """Velocities (rad/s) to fly through each waypoint; zero at both ends.

    Per joint: zero where the joint reverses direction at the waypoint, else the
    smaller of the mean rest-to-rest speeds of the two adjacent legs, capped at
    ``PASS_VELOCITY_FRACTION`` of the velocity limit.
    """
    from planner.costs import travel_time

    velocities = np.zeros_like(waypoints)
    if len(waypoints) < 3:
        return velocities
    deltas = np.diff(waypoints, axis=0)
    durations = travel_time(
        waypoints[:-1], waypoints[1:], limits.velocity, limits.acceleration, limits.jerk
    )
    speeds = np.abs(deltas) / np.maximum(durations, 1e-9)[:, None]
    same_sign = np.sign(deltas[:-1]) * np.sign(deltas[1:]) > 0
    magnitude = np.minimum(speeds[:-1], speeds[1:])
    magnitude = np.minimum(magnitude, PASS_VELOCITY_FRACTION * limits.velocity)
    velocities[1:-1] = np.where(same_sign, np.sign(deltas[1:]) * magnitude, 0.0)
    return velocities


def through_waypoints(
    waypoints: ArrayLike,
    limits: JointLimits,
    stops: ArrayLike | None = None,
    velocities: ArrayLike | None = None,
) -> TimedMotion:
    """Chain single-target ruckig calculations through ``waypoints`` (rad, shape (m, dof)).

    ``stops`` (bool, shape (m,)) forces rest at a waypoint; both ends always rest. A
    piece that ends and starts at rest uses phase synchronisation (straight line),
    others time synchronisation. ``velocities`` defaults to :func:`pass_velocities`.
    """
    points = np.atleast_2d(np.asarray(waypoints, dtype=float))
    m = len(points)
    stop_mask = np.zeros(m, dtype=bool) if stops is None else np.asarray(stops, dtype=bool).copy()
    stop_mask[0] = stop_mask[-1] = True
    vel = pass_velocities(points, limits) if velocities is None else np.asarray(velocities, float)
    vel = np.where(stop_mask[:, None], 0.0, vel)
    otg = ruckig.Ruckig(limits.dof)
    inp = _input(limits)
    inp.min_position = limits.lower
    inp.max_position = limits.upper
    pieces = []
    for k in range(m - 1):
        inp.current_position = points[k]
        inp.current_velocity = vel[k]
        inp.current_acceleration = np.zeros(limits.dof)
        inp.target_position = points[k + 1]
        inp.target_velocity = vel[k + 1]
        inp.target_acceleration = np.zeros(limits.dof)
        at_rest = stop_mask[k] and stop_mask[k + 1]
        inp.synchronization = (
            ruckig.Synchronization.Phase if at_rest else ruckig.Synchronization.Time
        )
        pieces.append(_calculate(otg, inp, f"path piece {k} of {m - 1}"))
    return TimedMotion(pieces, points, stop_mask)


def time_path(
    waypoints: ArrayLike,
    limits: JointLimits,
    motion_free: Callable[[NDArray[np.float64]], bool],
    dt: float,
) -> TimedMotion:
    """Time a collision-free waypoint path, flying through waypoints where that stays free.

    ``motion_free(samples)`` says whether the motion through the rows of ``samples``
    (consecutive configurations, rad) is collision-free. Each piece is sampled every
    ``dt`` s; a piece that is not free gets stops at both its ends (a rest-to-rest
    piece follows the straight, already validated line) and the path is re-timed.
    """
    points = np.atleast_2d(np.asarray(waypoints, dtype=float))
    stops = np.zeros(len(points), dtype=bool)
    velocities = pass_velocities(points, limits)
    for _ in range(len(points)):
        motion = through_waypoints(points, limits, stops, velocities)
        changed = False
        for k in range(len(points) - 1):
            if stops[k] and stops[k + 1]:
                continue
            if not motion_free(motion.piece_positions(k, dt)):
                stops[k] = stops[k + 1] = True
                changed = True
        if not changed:
            return motion
    return through_waypoints(points, limits, np.ones(len(points), dtype=bool))
