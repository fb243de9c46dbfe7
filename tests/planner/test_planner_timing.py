"""ruckig timing: straight segments stay straight, limits hold, waypoints are passed."""

from __future__ import annotations

import itertools

import numpy as np

from planner.timing import JointLimits, pass_velocities, rest_to_rest, through_waypoints, time_path
from planner.trajectory import Dwell, finite_difference_limits, sample_timeline

V = np.array([3.054, 3.054, 3.054, 6.283, 6.283, 8.727])
LIMITS = JointLimits(-np.full(6, 7.0), np.full(6, 7.0), V, 2.5 * V, 25.0 * V)
DT = 0.004
#: finite differences of a sampled jerk-limited motion stay within the limits up to rounding
TOL = 1e-6


def test_rest_to_rest_is_straight_and_within_limits() -> None:
    a, b = np.zeros(6), np.array([1.2, -0.4, 0.3, 2.0, -1.0, 0.5])
    motion = rest_to_rest(a, b, LIMITS)
    q = sample_timeline([motion], DT)
    s = (q - a) @ (b - a) / ((b - a) @ (b - a))
    assert np.max(np.linalg.norm(q - (a + s[:, None] * (b - a)), axis=1)) < 1e-9
    assert np.all(np.diff(s) >= -1e-12)  # moves forward only
    assert np.allclose(q[0], a) and np.allclose(q[-1], b)
    assert finite_difference_limits(q, DT, LIMITS).within(TOL)


def test_waypoints_are_passed_with_velocity_and_faster_than_stopping() -> None:
    w = np.array(
        [[0, 0, 0, 0, 0, 0], [1, 0.5, 0, 0, 0, 0], [2, 1.5, 0.3, 0, 0, 0], [2.5, 1.0, 0, 0, 0, 0]]
    )
    flying = through_waypoints(w, LIMITS)
    stopping = through_waypoints(w, LIMITS, stops=np.ones(4, dtype=bool))
    assert flying.duration < stopping.duration
    for k in range(4):
        assert np.allclose(flying.state(flying.piece_starts[k])[0], w[k], atol=1e-9)
    v_mid = flying.state(flying.piece_starts[1])[1]
    assert abs(v_mid[0]) > 0.1  # joint 1 keeps moving through the first waypoint
    q = sample_timeline([flying], DT)
    assert finite_difference_limits(q, DT, LIMITS).within(TOL)


def test_pass_velocity_is_zero_where_a_joint_reverses() -> None:
    w = np.array([[0.0] * 6, [1.0, 1.0, 0, 0, 0, 0], [2.0, 0.0, 0, 0, 0, 0]])
    v = pass_velocities(w, LIMITS)
    assert v[1, 0] > 0 and v[1, 1] == 0.0
    assert np.all(v[0] == 0) and np.all(v[-1] == 0)


def _distance_to_polyline(q: np.ndarray, w: np.ndarray) -> np.ndarray:
    best = np.full(len(q), np.inf)
    for a, b in itertools.pairwise(w):
        s = np.clip((q - a) @ (b - a) / ((b - a) @ (b - a)), 0.0, 1.0)
        best = np.minimum(best, np.linalg.norm(q - (a + s[:, None] * (b - a)), axis=1))
    return best


def test_time_path_stops_where_the_flying_motion_is_not_free() -> None:
    w = np.array([[0.0] * 6, [1.0, 0.2, 0, 0, 0, 0], [1.2, 1.2, 0, 0, 0, 0]])
    free = time_path(w, LIMITS, lambda samples: True, DT)
    assert not free.stops[1]
    # only the polyline itself (within 1 mrad) is free: cutting the corner is "in collision"
    corner = time_path(w, LIMITS, lambda s: bool(_distance_to_polyline(s, w).max() < 1e-3), DT)
    assert corner.stops[1]
    q = sample_timeline([corner], DT)
    assert _distance_to_polyline(q, w).max() < 1e-9
    assert corner.duration > free.duration
    assert finite_difference_limits(q, DT, LIMITS).within(TOL)


def test_timeline_with_dwell_is_sampled_at_dt() -> None:
    a, b = np.zeros(6), np.full(6, 0.3)
    m1, m2 = rest_to_rest(a, b, LIMITS), rest_to_rest(b, a, LIMITS)
    q = sample_timeline([m1, Dwell(b, 0.2), m2], DT)
    total = m1.duration + 0.2 + m2.duration
    assert len(q) == int(np.ceil(total / DT - 1e-9)) + 1
    mid = round((m1.duration + 0.1) / DT)
    assert np.allclose(q[mid], b)
    assert finite_difference_limits(q, DT, LIMITS).within(TOL)


def test_finite_difference_check_catches_a_too_fast_trajectory() -> None:
    q = np.outer(np.arange(100) * DT, np.full(6, 1.5 * V.max()))
    assert not finite_difference_limits(q, DT, LIMITS).within(TOL)


def test_positions_equal_state_sample_by_sample() -> None:
    """The batched ``positions`` gives ``state``'s positions bit for bit, before the start,
    on each piece's boundaries and after the end included."""
    rng = np.random.default_rng(3)
    W = rng.uniform(-1.0, 1.0, (5, 6))
    motion = through_waypoints(W, LIMITS, np.array([True, False, True, False, True]))
    assert len(motion.pieces) == 4
    t = np.concatenate(
        [[-0.1, 0.0], motion.piece_starts, rng.uniform(0, motion.duration, 50), [1e3]]
    )
    expected = np.array([motion.state(float(x))[0] for x in t])
    assert np.array_equal(motion.positions(t), expected)
    assert not np.array_equal(expected[2], expected[3])  # the samples differ (not one row)
