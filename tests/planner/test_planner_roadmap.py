"""Batch motion checks and the roadmap of detours among candidate configurations."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from cell.config import load_cell
from planner.edge_check import BatchEdgeChecker
from planner.paths import MotionChecker
from planner.roadmap import DETOUR_EXTRA_S, DETOUR_FACTOR, Roadmap, detour_costs, neighbour_pairs


@pytest.fixture(scope="module")
def arm():
    return load_cell(None).build_arm()


def test_batch_checks_equal_one_motion_at_a_time_on_the_built_in_cell(arm) -> None:
    checker = MotionChecker(arm, np.radians(1.5), 0.006)
    batch = BatchEdgeChecker(checker, threads=2)
    rng = np.random.default_rng(3)
    A = rng.uniform(arm.lower, arm.upper, (120, 6)) * 0.4
    B = np.clip(A + rng.normal(scale=0.4, size=A.shape), arm.lower, arm.upper)
    B[:5] = arm.upper + 0.1  # outside the limits at the end: not free
    got = batch.free(A, B)
    want = np.array([checker.segment_free(a, b, ends=True) for a, b in zip(A, B, strict=True)])
    assert got.tolist() == want.tolist()
    assert 0 < got.sum() < len(got)  # both answers occur
    assert batch.free(np.zeros((0, 6)), np.zeros((0, 6))).shape == (0,)


def test_blocked_motions_cost_their_shortest_detour_through_free_ones() -> None:
    # nodes 0 (home), 1..4 one per hole on a line; the direct 1-3 motion is blocked
    x = np.array([0.0, 1.0, 2.0, 3.0, 9.0])
    G = np.abs(x[:, None] - x[None, :])
    owner = np.array([-1, 0, 1, 2, 3])
    pairs = neighbour_pairs(G, owner, 2)
    assert (pairs[:, 0] < pairs[:, 1]).all() and [1, 3] in pairs.tolist()
    rm = Roadmap(free={(0, 1): True, (1, 2): True, (2, 3): True, (1, 3): False})
    costs = detour_costs(rm, G, [(1, 3), (3, 1), (1, 4)])
    assert costs[(1, 3)] == pytest.approx(2.0) and rm.via(1, 3) == [2]
    assert rm.via(3, 1) == [2]
    # node 4 is not on the roadmap: the estimate
    assert costs[(1, 4)] == pytest.approx(DETOUR_FACTOR * 8.0 + DETOUR_EXTRA_S)
    assert rm.via(1, 4) is None


def test_concatenated_linspaces_equal_numpy_linspace_bit_for_bit() -> None:
    from planner.sampling import linspaces

    n = np.array([1, 2, 3, 7, 10, 33, 129])
    want = np.concatenate([np.linspace(0.0, 1.0, m + 1) for m in n])
    assert np.array_equal(linspaces(n), want)


def test_polyline_in_one_batch_equals_segment_by_segment_one_configuration_at_a_time(arm) -> None:
    checker = MotionChecker(arm, np.radians(1.5), 0.006)
    rng = np.random.default_rng(4)

    def reference(P: np.ndarray) -> bool:  # every row and every segment's samples, one by one
        if not all(arm.within_limits(q) and not arm.in_collision(q) for q in P):
            return False
        for a, b in itertools.pairwise(P):
            Q = checker.samples(a, b)
            if not checker._inside(Q) or any(arm.in_collision(q) for q in Q[1:-1]):
                return False
        return True

    got, want = [], []
    for _ in range(40):
        P = [rng.uniform(arm.lower, arm.upper) * 0.4]
        for _ in range(rng.integers(1, 5)):
            P.append(P[-1] + rng.normal(scale=0.25, size=6))
        P = np.array(P)
        got.append(checker.polyline_free(P))
        want.append(reference(P))
    assert got == want
    assert 0 < sum(got) < len(got)  # both answers occur
