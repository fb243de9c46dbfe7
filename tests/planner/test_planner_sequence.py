"""Sequencing: exact configuration choice, local search moves, GTSP solvers on known truth."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from planner.costs import cost_matrix
from planner.errors import PlanningError
from planner.lns import GtspLns, LnsSettings, layered_nodes
from planner.local_search import (
    apply_or_opt,
    apply_two_opt,
    best_or_opt,
    best_two_opt,
    improve_order,
)
from planner.sequence import layered_best, sequence, tour_cost
from planner.timing import JointLimits

V = np.array([3.054, 3.054, 3.054, 6.283, 6.283, 8.727])
LIMITS = JointLimits(-np.full(6, 7.0), np.full(6, 7.0), V, 2.5 * V, 25.0 * V)
HOME = np.zeros(6)


def _instance(n: int, seed: int) -> list[np.ndarray]:
    rng = np.random.default_rng(seed)
    return [
        rng.uniform(-1.5, 1.5, 6) + rng.normal(0, 0.6, (int(rng.integers(1, 4)), 6))
        for _ in range(n)
    ]


def _brute_force(cands: list[np.ndarray]) -> float:
    best = np.inf
    for perm in itertools.permutations(range(len(cands))):
        for pick in itertools.product(*[range(len(cands[h])) for h in perm]):
            best = min(
                best,
                tour_cost(
                    HOME, np.array([cands[h][c] for h, c in zip(perm, pick, strict=False)]), LIMITS
                ),
            )
    return best


def test_layered_best_is_the_exact_optimum_for_a_fixed_order() -> None:
    cands = _instance(5, 1)
    choice, cost = layered_best(HOME, cands, LIMITS)
    brute = min(
        tour_cost(HOME, np.array([c[i] for c, i in zip(cands, pick, strict=False)]), LIMITS)
        for pick in itertools.product(*[range(len(c)) for c in cands])
    )
    assert cost == pytest.approx(brute, abs=1e-9)
    assert tour_cost(
        HOME, np.array([c[i] for c, i in zip(cands, choice, strict=False)]), LIMITS
    ) == pytest.approx(cost)


def _path_cost(C: np.ndarray, perm: list[int]) -> float:
    return float(sum(C[perm[k], perm[k + 1]] for k in range(len(perm) - 1)))


def test_local_search_deltas_match_the_applied_moves() -> None:
    rng = np.random.default_rng(5)
    P = rng.uniform(0, 1, (12, 2))
    C = np.linalg.norm(P[:, None] - P[None], axis=-1)
    ident = list(range(12))
    d, i, j = best_two_opt(C)
    assert _path_cost(C, apply_two_opt(ident, i, j)) == pytest.approx(_path_cost(C, ident) + d)
    for length in (1, 2, 3):
        d, i, j, rev = best_or_opt(C, length)
        moved = apply_or_opt(ident, i, length, j, rev)
        assert sorted(moved) == ident and moved[0] == 0 and moved[-1] == 11
        assert _path_cost(C, moved) == pytest.approx(_path_cost(C, ident) + d)
    perm = improve_order(C)
    assert perm[0] == 0 and perm[-1] == 11 and sorted(perm) == ident
    assert _path_cost(C, perm) <= _path_cost(C, ident)


@pytest.mark.parametrize("method", ["lns", "pyvrp", "ortools"])
def test_sequencers_find_the_brute_force_optimum_of_small_instances(method: str) -> None:
    for seed in (2, 3):
        cands = _instance(5, seed)
        res = sequence(HOME, cands, LIMITS, time_budget_s=5.0, seed=0, method=method)
        assert sorted(res.order) == list(range(5))
        assert all(0 <= c < len(cands[h]) for h, c in zip(res.order, res.choice, strict=False))
        assert res.cost_s == pytest.approx(_brute_force(cands), rel=1e-6)


def test_lns_is_deterministic_for_a_seed_and_visits_each_group_once() -> None:
    cands = _instance(30, 9)
    a = sequence(HOME, cands, LIMITS, time_budget_s=30.0, seed=4)
    b = sequence(HOME, cands, LIMITS, time_budget_s=30.0, seed=4)
    assert a.order == b.order and a.choice == b.choice and a.cost_s == b.cost_s
    assert sorted(a.order) == list(range(30))
    assert not a.hit_time_limit


def test_lns_improves_on_its_greedy_start() -> None:
    cands = _instance(25, 11)
    nodes = np.vstack([HOME[None], *cands])
    offsets = np.cumsum([1] + [len(c) for c in cands])
    groups = [np.arange(offsets[h], offsets[h] + len(c)) for h, c in enumerate(cands)]
    G = cost_matrix(nodes, nodes, LIMITS.velocity, LIMITS.acceleration, LIMITS.jerk)
    greedy = GtspLns(G, groups, 0).initial()
    best = GtspLns(G, groups, 0).run(LnsSettings(max_iterations=300, patience=100, time_limit_s=30))
    assert best.cost_s <= greedy[2] + 1e-9
    _again, cost = layered_nodes(G, [groups[h] for h in best.order])
    assert cost == pytest.approx(best.cost_s, rel=1e-9)


def test_sequencer_rejects_a_hole_without_candidates_and_unknown_methods() -> None:
    with pytest.raises(PlanningError):
        sequence(HOME, [np.zeros((0, 6))], LIMITS, 1.0, 0)
    with pytest.raises(PlanningError, match="unknown sequencing method"):
        sequence(HOME, _instance(3, 0), LIMITS, 1.0, 0, method="magic")
