"""The GTSP solved by PyVRP: one optional client per candidate node, one required group per hole.

PyVRP (iterated local search with the VRP neighbourhoods, including ``ReplaceGroup``
and ``RelocateAlternative`` for client groups) sees node 0 as the depot and every
candidate configuration as an optional client at its own location; each hole's
candidates form a required mutually exclusive group, so a feasible solution visits
exactly one configuration per hole. Costs are integers: travel time in units of
``COST_SCALE`` per second (10 µs). The search stops after a fixed number of
iterations (scaled by the instance size and ``effort``), so a seed gives the same
tour on any machine; the time limit is a hard cap on CPU time that only binds on a
slow machine.
"""

from __future__ import annotations

import time
from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray
from pyvrp import (
    Client,
    ClientGroup,
    Depot,
    Location,
    ProblemData,
    Solution,
    SolveParams,
    VehicleType,
    solve,
)
from pyvrp.search import NeighbourhoodParams
from pyvrp.stop import MaxIterations, MultipleCriteria

from planner.errors import PlanningError

#: integer cost units per second
COST_SCALE = 1e5
#: granular neighbourhood: this many nodes per largest group (PyVRP's default of 50 nearest
#: clients covers only three holes of 16 candidates each; measured: 250 neighbours find tours
#: 1–4 % shorter than 100 on the 40-hole cluttered cell at the same iterations)
NEIGHBOURS_PER_GROUP_NODE = 16


class MaxCpuTime:
    """PyVRP stopping criterion: this thread's CPU time exceeds ``limit_s`` (other jobs on a
    shared machine do not shorten the search, as they would with wall-clock ``MaxRuntime``)."""

    def __init__(self, limit_s: float) -> None:
        self.limit_s = limit_s
        self.started = time.thread_time()

    def __call__(self, best_cost: float) -> bool:
        return time.thread_time() - self.started > self.limit_s


def gtsp_data(G: NDArray[np.float64], groups: Sequence[NDArray[np.int64]]) -> ProblemData:
    """The PyVRP problem of the GTSP on nodes ``0..N-1`` (node 0 = home depot)."""
    N = G.shape[0]
    owner = np.full(N, -1, dtype=np.int64)
    for h, g in enumerate(groups):
        owner[np.asarray(g)] = h
    if (owner[1:] < 0).any():
        raise PlanningError("every node but home must belong to a hole")
    D = np.rint(np.asarray(G, dtype=float) * COST_SCALE).astype(np.int64)
    np.fill_diagonal(D, 0)
    return ProblemData(
        locations=[Location(0, 0) for _ in range(N)],
        clients=[Client(location=i, required=False, group=int(owner[i])) for i in range(1, N)],
        depots=[Depot(location=0)],
        vehicle_types=[VehicleType(1)],
        # pyvrp's stub spells the matrices np.ndarray[int] (int as the shape parameter)
        distance_matrices=[D],  # type: ignore[list-item]
        duration_matrices=[np.zeros_like(D)],  # type: ignore[list-item]
        groups=[ClientGroup([int(v) - 1 for v in g], required=True) for g in groups],
    )


def solve_gtsp_pyvrp(
    G: NDArray[np.float64],
    groups: Sequence[NDArray[np.int64]],
    iterations: int,
    time_limit_s: float,
    seed: int,
    warm: Sequence[int] | None = None,
) -> tuple[list[int], bool]:
    """Visited nodes in order (depot excluded) and whether the time cap stopped the search.

    ``warm`` (visited nodes) is the initial solution; PyVRP starts from it.
    """
    data = gtsp_data(G, groups)
    initial = Solution(data, [[int(v) - 1 for v in warm]]) if warm else None  # client indices
    stop = MultipleCriteria([MaxIterations(max(int(iterations), 1)), MaxCpuTime(time_limit_s)])
    largest = max(len(g) for g in groups)
    hood = NeighbourhoodParams(
        num_neighbours=min(G.shape[0] - 1, NEIGHBOURS_PER_GROUP_NODE * largest)
    )
    res = solve(
        data, stop=stop, seed=int(seed), collect_stats=False, display=False,
        initial_solution=initial, params=SolveParams(neighbourhood=hood),
    )  # fmt: skip
    if not res.best.is_feasible():
        raise PlanningError("PyVRP found no tour visiting every hole once")
    routes = res.best.routes()
    # schedule indices are 0-based client indices; client c sits at node c + 1
    visited = [a.idx + 1 for a in routes[0].schedule() if a.is_client()] if routes else []
    return [int(v) for v in visited], res.num_iterations < iterations
