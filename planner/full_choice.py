"""The sequencer's polish: every IK candidate for the found order, and a task-space start.

The GTSP search (:mod:`planner.lns`) works with ``nodes_per_hole`` representatives of
each hole's candidate configurations (a few hundred per hole: roll samples × IK
branches), spread out in travel time. Two things it misses, measured on the built-in
frame (41 holes, seed 0; rest-to-rest sequence costs):

- the best configuration for an order is usually *not* a representative: re-choosing
  over every candidate for the search's own order shortens it from 19.21 s to 18.53 s;
- a task-space order (a TSP over the viewpoint positions) is a better start than the
  greedy nearest node: with every candidate it costs 18.09 s (the benchmark's
  "published" method), and the search started from it reaches 17.96 s (before the
  lazy collision checks).

So before the search (:meth:`planner.sequence.GtspSequencer.add_task_space_nodes`, in the
seed-independent part, so that the roadmap checks their motions like every node's) the
configurations of the task-space tour with every candidate join the nodes; after it: the
exact layered shortest path over *every* candidate of each
hole for the found order (:func:`layered_choice`, costs from the planner's lookup table);
the chosen configurations join their holes' nodes; a search warm-started from that tour
(its layered step now sees them) improves the order; repeated while it gains. The same
from the task-space order (:func:`task_space_order`). The best tour of all is kept, so
the result is never worse than the search alone. Deterministic: no clock, no randomness
beyond the search's seeded generator.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray
from ortools.constraint_solver import pywrapcp, routing_enums_pb2

from planner.costs import CostTable

#: solutions of the task-space TSP's search (0.17 s at 41 holes; the same tour as 1.6 s of
#: the benchmark's time-limited search, which this limit makes deterministic)
TSP_SOLUTIONS = 100


def layered_choice(
    table: CostTable,
    home_q: NDArray[np.float64],
    layers: Sequence[NDArray[np.float64]],
) -> tuple[list[int], float]:
    """Best candidate row per layer (rad rows) for a fixed order, home at both ends: the
    exact layered shortest path over the table's travel times (s). Returns rows and cost."""
    if not layers:
        return [], 0.0
    dist = table.matrix(home_q[None, :], layers[0])[0].astype(np.float64)
    back: list[NDArray[np.int64]] = []
    for prev, cur in itertools.pairwise(layers):
        total = dist[:, None] + table.matrix(prev, cur)
        arg = np.argmin(total, axis=0)
        back.append(arg)
        dist = total[arg, np.arange(len(cur))]
    total = dist + table.matrix(layers[-1], home_q[None, :])[:, 0]
    last = int(np.argmin(total))
    rows = [last]
    for arg in reversed(back):
        rows.append(int(arg[rows[-1]]))
    return rows[::-1], float(total[last])


def task_space_order(positions_m: NDArray[np.float64], time_cap_s: float = 60.0) -> list[int]:
    """A short tour through viewpoint positions (row 0: home TCP, row h + 1: hole h; m):
    OR-Tools routing (cheapest arc, then guided local search) stopped after
    ``TSP_SOLUTIONS`` solutions, a work limit (``time_cap_s`` only binds on a crawling
    machine). Returns the hole order."""
    P = np.asarray(positions_m, dtype=np.float64)
    dist = np.rint(np.linalg.norm(P[:, None, :] - P[None, :, :], axis=-1) * 1e6).astype(np.int64)
    manager = pywrapcp.RoutingIndexManager(len(P), 1, 0)
    routing = pywrapcp.RoutingModel(manager)
    routing.SetArcCostEvaluatorOfAllVehicles(routing.RegisterTransitMatrix(dist.tolist()))
    params = pywrapcp.DefaultRoutingSearchParameters()
    params.first_solution_strategy = routing_enums_pb2.FirstSolutionStrategy.PATH_CHEAPEST_ARC
    params.local_search_metaheuristic = (
        routing_enums_pb2.LocalSearchMetaheuristic.GUIDED_LOCAL_SEARCH
    )
    params.solution_limit = TSP_SOLUTIONS
    params.time_limit.FromMilliseconds(max(int(time_cap_s * 1000), 1))
    solution = routing.SolveWithParameters(params)
    order, index = [], solution.Value(routing.NextVar(routing.Start(0)))
    while not routing.IsEnd(index):
        order.append(manager.IndexToNode(index) - 1)
        index = solution.Value(routing.NextVar(index))
    return order
