"""Batch collision checks and the fast TCP positions equal the one-at-a-time answers."""

from __future__ import annotations

import numpy as np
import pytest

from cell.config import load_cell
from robots.collision_batch import PARALLEL_MIN_CONFIGS, BatchCollision


@pytest.fixture(scope="module")
def arm():
    return load_cell(None).build_arm()


def test_tcp_positions_equal_the_tcp_of_the_full_forward_kinematics(arm) -> None:
    Q = np.random.default_rng(5).uniform(arm.lower, arm.upper, (400, 6))
    want = arm.fk_dh(Q, "tcp")[:, :3, 3]
    assert np.abs(arm.tcp_positions(Q) - want).max() < 1e-12


def test_each_configuration_in_one_call_equals_in_collision(arm) -> None:
    rng = np.random.default_rng(8)
    Q = rng.uniform(arm.lower, arm.upper, (300, 6))
    want = np.array([arm.in_collision(q) for q in Q])
    got = arm.in_collision_each(Q)
    assert got.tolist() == want.tolist()
    assert 0 < got.sum() < len(got)  # both answers occur
    assert arm.in_collision_each(np.zeros((0, 6))).shape == (0,)


def test_trajectories_stop_at_a_collision_on_one_or_two_threads(arm) -> None:
    rng = np.random.default_rng(9)
    Q = rng.uniform(arm.lower, arm.upper, (40, 6))
    want = np.array([arm.in_collision(q) for q in Q])
    trajs = [Q[i : i + 4].T for i in range(0, 40, 4)]
    expect = [bool(want[i : i + 4].any()) for i in range(0, 40, 4)]
    batch = BatchCollision(arm.collision, threads=2)
    assert batch.any_hit(trajs).tolist() == expect  # a small batch: one thread
    big = trajs * (PARALLEL_MIN_CONFIGS // 40 + 1)  # a large one: both threads
    assert batch.any_hit(big).tolist() == expect * (PARALLEL_MIN_CONFIGS // 40 + 1)
    assert batch.any_hit([np.zeros((6, 0))]).tolist() == [False]
