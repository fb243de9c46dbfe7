"""Viewpoint poses and a hole's candidates: the batched forms give the plain loops' numbers."""

from __future__ import annotations

import numpy as np

from cell.config import load_builtin_cell
from planner.viewpoints import _basis, hole_candidates, view_directions, viewpoint_poses


def _poses_one_by_one(position_m, normal, standoff_m, roll_step_deg, tilt_deg, azimuths):
    """The pose of each roll of each direction, one 4x4 at a time (the reference)."""
    poses = []
    for z in view_directions(normal, tilt_deg, azimuths):
        x0, y0 = _basis(z)
        for roll in np.radians(np.arange(0.0, 360.0 - 1e-9, roll_step_deg)):
            c, s = np.cos(roll), np.sin(roll)
            T = np.eye(4)
            T[:3, :3] = np.column_stack((c * x0 + s * y0, -s * x0 + c * y0, z))
            T[:3, 3] = np.asarray(position_m, dtype=float) - standoff_m * z
            poses.append(T)
    return np.array(poses)


def test_viewpoint_poses_equal_the_pose_by_pose_loop() -> None:
    rng = np.random.default_rng(1)
    for k in range(40):
        n = rng.normal(size=3)
        args = (rng.uniform(-1, 1, 3), n / np.linalg.norm(n), 0.3, (15.0, 7.5)[k % 2])
        tilt = (0.0, 10.0)[k // 2 % 2]
        got = viewpoint_poses(*args, tilt, 6)
        rolls = 24 if k % 2 == 0 else 48
        assert got.shape == (rolls * (7 if tilt else 1), 4, 4)
        assert np.array_equal(got, _poses_one_by_one(*args, tilt, 6))


class _OnePoseAtATime:
    """The arm without its batched IK (``ik_many``): hole_candidates solves pose by pose."""

    def __init__(self, arm) -> None:
        self._arm = arm

    def __getattr__(self, name: str):
        if name == "ik_many":
            raise AttributeError(name)
        return getattr(self._arm, name)


def test_hole_candidates_with_batched_ik_equal_pose_by_pose() -> None:
    cell = load_builtin_cell()
    arm = cell.build_arm()
    slow = _OnePoseAtATime(arm)
    holes = cell.holes_in_cell()
    assert not hasattr(slow, "ik_many") and hasattr(arm, "ik_many")
    for hole in holes[::4]:
        for tilt in (0.0, 10.0):
            a = hole_candidates(arm, hole, cell.tool.standoff_m, 15.0, tilt)
            b = hole_candidates(slow, hole, cell.tool.standoff_m, 15.0, tilt)
            assert a.ok == b.ok and a.reason == b.reason
            for x, y in ((a.q, b.q), (a.branch, b.branch), (a.pose, b.pose)):
                assert np.array_equal(x, y)
