"""The sequencer's polish: every candidate for an order, added nodes, the task-space start."""

from __future__ import annotations

import numpy as np
import pytest

from planner.full_choice import layered_choice, task_space_order
from planner.lns import GtspLns, LnsSettings
from planner.sequence import GtspSequencer, layered_best, tour_cost
from planner.timing import JointLimits

V = np.array([3.054, 3.054, 3.054, 6.283, 6.283, 8.727])
LIMITS = JointLimits(-np.full(6, 7.0), np.full(6, 7.0), V, 2.5 * V, 25.0 * V)
HOME = np.zeros(6)


def _instance(n: int, per_hole: int, seed: int) -> tuple[list[np.ndarray], np.ndarray]:
    """Holes with many candidates each (a roll sweep: one joint varies), and positions."""
    rng = np.random.default_rng(seed)
    cands, xyz = [], [np.zeros(3)]
    for _ in range(n):
        base = rng.uniform(-1.5, 1.5, 6)
        c = np.repeat(base[None], per_hole, axis=0) + rng.normal(0, 0.05, (per_hole, 6))
        c[:, 5] = np.linspace(-3.0, 3.0, per_hole)
        c[: per_hole // 2, 0] += rng.choice([-1.0, 1.0])  # a second IK branch
        cands.append(c)
        xyz.append(0.3 * base[:3])
    return cands, np.array(xyz)


def _sequencer(cands, xyz=None, per_hole: int = 3) -> GtspSequencer:
    return GtspSequencer(HOME, cands, LIMITS, nodes_per_hole=per_hole, positions_m=xyz)


def test_layered_choice_is_the_exact_layered_optimum_up_to_the_table() -> None:
    cands, _ = _instance(8, 12, 1)
    seqr = _sequencer(cands)
    rows, cost = layered_choice(seqr.table, HOME, cands)
    _, exact = layered_best(HOME, cands, LIMITS)
    assert cost == pytest.approx(exact, abs=1e-3)  # table step: ~1e-4 s per motion
    chosen = np.array([c[r] for c, r in zip(cands, rows, strict=True)])
    assert tour_cost(HOME, chosen, LIMITS) == pytest.approx(exact, abs=1e-3)


def test_added_nodes_join_their_groups_with_table_costs_once() -> None:
    cands, _ = _instance(6, 10, 2)
    seqr = _sequencer(cands)
    n0 = len(seqr.nodes)
    fresh = [(h, next(r for r in range(10) if r not in seqr.reps[h])) for h in range(6)]
    old = [(1, int(seqr.reps[1][0]))]  # already a node: its id comes back
    picks = fresh + old
    new = seqr.add_nodes(picks)
    assert len(seqr.nodes) == seqr.G.shape[0] == seqr.G.shape[1] == n0 + 6
    assert new[:6] == list(range(n0, n0 + 6)) and new[6] < n0
    for (h, k), v in zip(picks, new, strict=True):
        assert seqr.owner[v] == h and seqr.local[v] == k and v in seqr.groups[h]
        np.testing.assert_array_equal(seqr.nodes[v], cands[h][k])
    block = seqr.table.matrix(seqr.nodes[new], seqr.nodes)
    np.testing.assert_allclose(seqr.G[new], block, rtol=0, atol=0)
    assert seqr.add_nodes(picks) == new and len(seqr.nodes) == n0 + 6


def test_polished_tour_is_no_worse_than_the_search_and_deterministic() -> None:
    cands, xyz = _instance(20, 24, 3)
    plain = _sequencer(cands, xyz)
    settings = LnsSettings(max_iterations=200 + 4 * 20, patience=50 + 20, time_limit_s=60.0)
    searched = GtspLns(plain.G, plain.groups, 0).run(settings)
    a, b = _sequencer(cands, xyz), _sequencer(cands, xyz)
    for s in (a, b):
        s.add_task_space_nodes()
    ra, rb = a.solve(60.0, 0), b.solve(60.0, 0)
    assert ra.order == rb.order and ra.choice == rb.choice and ra.cost_s == rb.cost_s
    assert sorted(ra.order) == list(range(20))
    assert ra.cost_s <= plain.cost_of(searched.nodes) + 1e-9
    chosen = np.array([cands[h][k] for h, k in zip(ra.order, ra.choice, strict=True)])
    assert tour_cost(HOME, chosen, LIMITS) == pytest.approx(ra.cost_s, rel=1e-12)
    # the task-space start's configurations are nodes (checked by the roadmap with the rest)
    assert a.task_order is not None and sorted(a.task_order) == list(range(20))
    rows, _ = layered_choice(a.table, HOME, [cands[h] for h in a.task_order])
    for h, r in zip(a.task_order, rows, strict=True):
        assert any(a.local[v] == r for v in a.groups[h])


def test_task_space_order_is_a_short_tour() -> None:
    rng = np.random.default_rng(4)
    P = rng.uniform(0, 1, (30, 3))
    order = task_space_order(P)
    assert sorted(order) == list(range(29))
    path = [0, *[h + 1 for h in order], 0]
    length = np.linalg.norm(P[path[1:]] - P[path[:-1]], axis=1).sum()
    ident = np.linalg.norm(P[1:] - P[:-1], axis=1).sum() + np.linalg.norm(P[-1] - P[0])
    assert length < 0.6 * ident and task_space_order(P) == order
