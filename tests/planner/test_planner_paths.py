"""Segment paths: the straight segment when free, else OMPL around an obstacle (generic arm)."""

from __future__ import annotations

import numpy as np
import pytest

from planner.errors import SegmentPlanningError
from planner.paths import MotionChecker, SegmentPlanner, seed_ompl


class _JointSpaceArm:
    """A stand-in arm: a 'TCP' at (q1, q2, q3) m and a box obstacle in joint space."""

    joint_names = tuple(f"joint_{i}" for i in range(1, 7))
    lower = np.full(6, -2.0)
    upper = np.full(6, 2.0)

    def __init__(self, box_lo: np.ndarray, box_hi: np.ndarray) -> None:
        self.box_lo, self.box_hi = box_lo, box_hi

    def within_limits(self, q: np.ndarray, tol: float = 1e-9) -> bool:
        return bool(np.all(q >= self.lower - tol) and np.all(q <= self.upper + tol))

    def in_collision(self, q: np.ndarray) -> bool:
        return bool(np.all(q >= self.box_lo) and np.all(q <= self.box_hi))

    def fk_dh(self, Q: np.ndarray, frame: str = "tcp") -> np.ndarray:
        Q = np.atleast_2d(Q)
        T = np.repeat(np.eye(4)[None], len(Q), axis=0)
        T[:, :3, 3] = Q[:, :3]
        return T


WALL = _JointSpaceArm(np.array([-0.1, -1.0, -2.0, -2, -2, -2]), np.array([0.1, 1.0, 2.0, 2, 2, 2]))


def test_motion_checker_resolution_in_joints_and_tcp() -> None:
    checker = MotionChecker(WALL, joint_step_rad=np.radians(0.5), tcp_step_m=0.002)
    Q = checker.samples(np.zeros(6), np.array([0.0, 0.0, 0.0, 0.0, 0.0, 1.0]))
    assert np.abs(np.diff(Q, axis=0)).max() <= np.radians(0.5) + 1e-12
    Q = checker.samples(np.zeros(6), np.array([0.5, 0.0, 0.0, 0.0, 0.0, 0.0]))
    assert np.linalg.norm(np.diff(Q[:, :3], axis=0), axis=1).max() <= 0.002 + 1e-12
    assert not checker.segment_free(
        np.array([-0.5, 0, 0, 0, 0, 0.0]), np.array([0.5, 0, 0, 0, 0, 0.0])
    )
    assert checker.segment_free(
        np.array([-0.5, 1.5, 0, 0, 0, 0.0]), np.array([0.5, 1.5, 0, 0, 0, 0.0])
    )


def test_straight_segment_when_free_else_an_ompl_path_around_the_wall() -> None:
    seed_ompl(0)
    checker = MotionChecker(WALL, np.radians(2.0), 0.01)
    planner = SegmentPlanner(checker, WALL.lower, WALL.upper)
    a, b = np.array([-0.5, 0, 0, 0, 0, 0.0]), np.array([0.5, 0, 0, 0, 0, 0.0])
    straight = planner.plan(a, a + 0.1 * np.array([0, 1, 0, 0, 0, 0]), 1.0, ("H1", "H2"))
    assert not straight.planned and len(straight.waypoints) == 2
    path = planner.plan(a, b, 5.0, ("H1", "H2"))
    assert path.planned and len(path.waypoints) >= 3
    assert np.allclose(path.waypoints[0], a) and np.allclose(path.waypoints[-1], b)
    assert checker.polyline_free(path.waypoints)
    assert np.abs(path.waypoints[:, 1]).max() > 1.0  # it went around the wall


def test_unsolvable_segment_names_both_holes() -> None:
    seed_ompl(0)

    # the goal sits inside a closed shell: every way in is blocked
    class _Shell(_JointSpaceArm):
        def in_collision(self, q: np.ndarray) -> bool:
            r = np.abs(q - 1.0).max()
            return bool(0.2 <= r <= 0.4)

    arm = _Shell(np.zeros(6), np.zeros(6))
    planner = SegmentPlanner(MotionChecker(arm, np.radians(2.0), 0.01), arm.lower, arm.upper)
    with pytest.raises(SegmentPlanningError, match="H7 to H8") as err:
        planner.plan(np.full(6, -1.0), np.full(6, 1.0), 0.3, ("H7", "H8"))
    assert (err.value.hole_a, err.value.hole_b) == ("H7", "H8")
