"""Tour sequencing: a generalised TSP over the candidate configurations of each hole.

One configuration per hole, each hole once, from home back to home, minimising
the sum of rest-to-rest travel times (:mod:`planner.costs`). OR-Tools routing
solves it with one mandatory disjunction per hole over that hole's candidate
configurations (at most ``max_nodes_per_hole`` of them, chosen far apart in
travel time). The order it returns is then refined exactly over *all*
candidates of each hole by a layered shortest path (dynamic programming).

The search is deterministic for a seed: OR-Tools stops after a number of
local-search solutions that depends on the problem size and the time budget,
not on the clock; the time budget is a hard cap that only binds on a loaded
machine (``SequenceResult.hit_time_limit`` reports it).
"""

from __future__ import annotations

import itertools
import time
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from ortools.constraint_solver import pywrapcp, routing_enums_pb2

from planner.costs import CostTable, cost_matrix, travel_time
from planner.errors import PlanningError
from planner.lns import GtspLns, LnsSettings
from planner.timing import JointLimits

#: integer cost units per second handed to OR-Tools (10 µs resolution)
COST_SCALE = 1e5


@dataclass(frozen=True)
class SequenceResult:
    """Visiting order and configuration choice.

    ``order[i]`` is the index (into the candidate list) of the i-th hole visited,
    ``choice[i]`` the row of that hole's candidate array used. ``cost_s`` is the sum
    of rest-to-rest travel times home → holes → home (s).
    """

    order: list[int]
    choice: list[int]
    cost_s: float
    time_s: float
    hit_time_limit: bool


def tour_cost(
    home_q: NDArray[np.float64], configs: NDArray[np.float64], limits: JointLimits
) -> float:
    """Sum of rest-to-rest travel times (s) home → ``configs`` rows in order → home."""
    path = np.vstack([home_q, configs, home_q])
    lim = (limits.velocity, limits.acceleration, limits.jerk)
    return float(travel_time(path[:-1], path[1:], *lim).sum())


def layered_best(
    home_q: NDArray[np.float64],
    layers: Sequence[NDArray[np.float64]],
    limits: JointLimits,
) -> tuple[list[int], float]:
    """Best configuration per hole for a fixed order: exact layered shortest path.

    ``layers[i]`` holds the candidate configurations (k_i, dof) of the i-th hole in
    visiting order. Returns the chosen row per layer and the closed tour cost (s).
    """
    lim = (limits.velocity, limits.acceleration, limits.jerk)
    if not layers:
        return [], 0.0
    dist = cost_matrix(home_q[None, :], layers[0], *lim)[0]
    back: list[NDArray[np.int64]] = []
    for prev, cur in itertools.pairwise(layers):
        total = dist[:, None] + cost_matrix(prev, cur, *lim)
        arg = np.argmin(total, axis=0)
        back.append(arg)
        dist = total[arg, np.arange(len(cur))]
    total = dist + cost_matrix(layers[-1], home_q[None, :], *lim)[:, 0]
    last = int(np.argmin(total))
    choice = [last]
    for arg in reversed(back):
        choice.append(int(arg[choice[-1]]))
    return choice[::-1], float(total[last])


def representatives(
    candidates: NDArray[np.float64], k: int, anchor: NDArray[np.float64], limits: JointLimits
) -> NDArray[np.int64]:
    """Indices of at most ``k`` candidates spread out in travel time (farthest-point sampling).

    Starts from the candidate nearest ``anchor`` (rad), so the choice is deterministic.
    """
    n = len(candidates)
    if n <= k:
        return np.arange(n)
    lim = (limits.velocity, limits.acceleration, limits.jerk)
    chosen = [int(np.argmin(travel_time(candidates, anchor, *lim)))]
    nearest = travel_time(candidates, candidates[chosen[0]], *lim)
    for _ in range(k - 1):
        nxt = int(np.argmax(nearest))
        chosen.append(nxt)
        nearest = np.minimum(nearest, travel_time(candidates, candidates[nxt], *lim))
    return np.array(sorted(chosen))


def _search_parameters(time_limit_s: float, solution_limit: int) -> object:
    params = pywrapcp.DefaultRoutingSearchParameters()
    params.first_solution_strategy = (
        routing_enums_pb2.FirstSolutionStrategy.PARALLEL_CHEAPEST_INSERTION
    )
    params.local_search_metaheuristic = (
        routing_enums_pb2.LocalSearchMetaheuristic.GUIDED_LOCAL_SEARCH
    )
    params.time_limit.FromMilliseconds(max(int(time_limit_s * 1000), 1))
    params.solution_limit = solution_limit
    return params


def solve_gtsp(
    cost_s: NDArray[np.float64],
    groups: Sequence[NDArray[np.int64]],
    time_limit_s: float,
    solution_limit: int,
    seed: int,
) -> tuple[list[int], bool]:
    """Solve a GTSP on nodes ``0..N-1`` (node 0 = home depot) with OR-Tools routing.

    ``groups[h]`` lists the nodes of hole h; exactly one per group is visited. The
    seed permutes the node numbering (OR-Tools breaks ties by index). Returns the
    visited nodes in order (depot excluded) and whether the time limit stopped the search.
    """
    n = cost_s.shape[0]
    rng = np.random.default_rng(seed)
    perm = np.concatenate([[0], 1 + rng.permutation(n - 1)])  # solver index -> node
    inv = np.empty(n, dtype=np.int64)
    inv[perm] = np.arange(n)
    scaled = np.rint(cost_s[np.ix_(perm, perm)] * COST_SCALE).astype(np.int64)
    manager = pywrapcp.RoutingIndexManager(n, 1, 0)
    routing = pywrapcp.RoutingModel(manager)
    transit = routing.RegisterTransitMatrix(scaled.tolist())
    routing.SetArcCostEvaluatorOfAllVehicles(transit)
    for group in groups:
        routing.AddDisjunction([manager.NodeToIndex(int(inv[g])) for g in group])
    started = time.perf_counter()
    solution = routing.SolveWithParameters(_search_parameters(time_limit_s, solution_limit))
    elapsed = time.perf_counter() - started
    if solution is None:
        raise PlanningError(f"the sequencer found no tour within {time_limit_s:.1f} s")
    order = []
    index = solution.Value(routing.NextVar(routing.Start(0)))
    while not routing.IsEnd(index):
        order.append(int(perm[manager.IndexToNode(index)]))
        index = solution.Value(routing.NextVar(index))
    return order, elapsed >= time_limit_s * 0.98


def sequence(
    home_q: NDArray[np.float64],
    candidates: Sequence[NDArray[np.float64]],
    limits: JointLimits,
    time_budget_s: float,
    seed: int,
    nodes_per_hole: int = 16,
    effort: float = 1.0,
    method: str = "lns",
    final_nodes_per_hole: int = 16,
) -> SequenceResult:
    """Order the holes and choose one configuration each (see module docstring).

    ``candidates[h]`` holds hole h's collision-free configurations (k_h, dof), rad.
    ``method`` is ``"lns"`` (:mod:`planner.lns`, the default) or ``"ortools"``
    (routing with one disjunction per hole). ``effort`` scales the search work.
    """
    started = time.perf_counter()
    home_q = np.asarray(home_q, dtype=float)
    if any(len(c) == 0 for c in candidates):
        raise PlanningError("every hole handed to the sequencer needs a candidate configuration")
    if not candidates:
        return SequenceResult([], [], 0.0, 0.0, False)
    table = CostTable(
        limits.velocity, limits.acceleration, limits.jerk, limits.upper - limits.lower
    )
    reps = [representatives(c, nodes_per_hole, home_q, limits) for c in candidates]
    nodes = np.vstack([home_q[None, :]] + [c[r] for c, r in zip(candidates, reps, strict=True)])
    owner = np.concatenate([[-1]] + [np.full(len(r), h) for h, r in enumerate(reps)]).astype(int)
    offsets = np.cumsum([1] + [len(r) for r in reps])
    groups = [np.arange(offsets[h], offsets[h] + len(r)) for h, r in enumerate(reps)]
    G = table.matrix(nodes, nodes)
    n = len(candidates)
    if method == "lns":
        settings = LnsSettings(
            max_iterations=int(effort * (300 + 8 * n)),
            patience=int(effort * (60 + 2 * n)),
            time_limit_s=time_budget_s,
        )
        found = GtspLns(G, groups, seed).run(settings)
        visited, hit = found.nodes, found.hit_time_limit
    elif method == "ortools":
        limit = int(effort * (200 + 5 * n))
        visited, hit = solve_gtsp(G.astype(float), groups, time_budget_s, limit, seed)
    else:
        raise PlanningError(f"unknown sequencing method {method!r} (use 'lns' or 'ortools')")
    order = [int(owner[v]) for v in visited]
    # exact configuration choice for this order over (nearly) every candidate
    rows = [representatives(candidates[h], final_nodes_per_hole, home_q, limits) for h in order]
    layers = [candidates[h][r] for h, r in zip(order, rows, strict=True)]
    picked, _ = layered_best(home_q, layers, limits)
    choice = [int(r[c]) for r, c in zip(rows, picked, strict=True)]
    cost = tour_cost(
        home_q, np.array([candidates[h][c] for h, c in zip(order, choice, strict=True)]), limits
    )
    lns_choice = [int(reps[owner[v]][v - offsets[owner[v]]]) for v in visited]
    lns_cost = tour_cost(home_q, nodes[visited], limits)
    if lns_cost < cost:
        choice, cost = lns_choice, lns_cost
    return SequenceResult(order, choice, cost, time.perf_counter() - started, hit)
