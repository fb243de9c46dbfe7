"""The PyVRP GTSP model: one optional client per node, one required group per hole."""

from __future__ import annotations

import numpy as np

from planner.pyvrp_gtsp import solve_gtsp_pyvrp
from planner.sequence import GtspSequencer
from planner.timing import JointLimits

V = np.array([3.054, 3.054, 3.054, 6.283, 6.283, 8.727])
LIMITS = JointLimits(-np.full(6, 7.0), np.full(6, 7.0), V, 2.5 * V, 25.0 * V)


def _sequencer(n: int, seed: int) -> GtspSequencer:
    rng = np.random.default_rng(seed)
    cands = [rng.uniform(-1.5, 1.5, 6) + rng.normal(0, 0.6, (4, 6)) for _ in range(n)]
    return GtspSequencer(np.zeros(6), cands, LIMITS, 16, "pyvrp")


def test_one_node_per_hole_same_seed_same_tour_and_a_warm_start_is_kept() -> None:
    sq = _sequencer(25, 5)
    a, hit_a = solve_gtsp_pyvrp(sq.G, sq.groups, 300, 30.0, seed=3)
    b, _ = solve_gtsp_pyvrp(sq.G, sq.groups, 300, 30.0, seed=3)
    assert a == b and not hit_a
    assert sorted(int(sq.owner[v]) for v in a) == list(range(25))
    # costs are what PyVRP optimises: the tour is no worse than a warm start it was given
    warm = [int(g[0]) for g in sq.groups]
    c, _ = solve_gtsp_pyvrp(sq.G, sq.groups, 50, 30.0, seed=0, warm=warm)
    assert sq.cost_of(c) <= sq.cost_of(warm) + 1e-4
    assert sq.cost_of(c) < 0.9 * sq.cost_of(warm)  # file order is far from good
