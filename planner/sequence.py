"""Tour sequencing: a generalised TSP over the candidate configurations of each hole.

One configuration per hole, each hole once, from home back to home, minimising
the sum of travel times (:mod:`planner.costs`: ruckig's rest-to-rest duration,
computed in closed form; measured durations replace it for segments that needed
a detour, see :meth:`GtspSequencer.learn`). Each hole contributes at most
``nodes_per_hole`` candidate configurations, chosen far apart in travel time.

Two solvers: the default large-neighbourhood search (:mod:`planner.lns`) and
OR-Tools routing with one mandatory disjunction per hole. Both are
deterministic for a seed: they stop after an amount of work that depends on the
problem size and the effort setting, not on the clock; the time budget is a
hard cap that only binds on a slow or loaded machine
(``SequenceResult.hit_time_limit`` reports it).
"""

from __future__ import annotations

import itertools
import time
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from ortools.constraint_solver import pywrapcp, routing_enums_pb2

from planner.costs import cost_matrix, cost_table, travel_time
from planner.errors import PlanningError
from planner.full_choice import layered_choice, task_space_order
from planner.helper import Helper
from planner.lns import NEAR_ABOVE, GtspLns, LnsSettings, near_holes
from planner.pyvrp_gtsp import solve_gtsp_pyvrp
from planner.representatives import every_representatives
from planner.shared_costs import symmetric_costs
from planner.timing import JointLimits

#: integer cost units per second handed to OR-Tools (10 µs resolution)
COST_SCALE = 1e5
#: the sequencing methods
SEQUENCERS = ("pyvrp", "lns", "ortools")
#: PyVRP iterations: base + per hole (a full solve; a repair after costs changed: a fifth)
PYVRP_ITERATIONS = (500, 20)
#: the polish over every candidate (:mod:`planner.full_choice`) runs up to this many holes
#: (its layered pass costs ~5 ms per hole; above, the search's near-hole moves already beat
#: the task-space baseline by 9 % at 250 holes) and at most this many rounds per start
POLISH_MAX_HOLES = 120
POLISH_ROUNDS = 4
#: work of the polish's searches: the full search's divided by this, for the first search
#: from the task-space tour and for the others (warm starts near a local optimum)
POLISH_WORK = (1, 4)


@dataclass(frozen=True)
class SequenceResult:
    """Visiting order and configuration choice.

    ``order[i]`` is the index (into the candidate list) of the i-th hole visited,
    ``choice[i]`` the row of that hole's candidate array used. ``cost_s`` is the sum
    of rest-to-rest travel times home → holes → home (s), with measured costs where
    the sequencer learned them. ``nodes`` are the sequencer's node ids, if it has any.
    """

    order: list[int]
    choice: list[int]
    cost_s: float
    time_s: float
    hit_time_limit: bool
    nodes: list[int] | None = None


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


class GtspSequencer:
    """The GTSP of one cell: candidate nodes, their cost matrix, and repeated solves.

    Node 0 is home; hole h owns ``groups[h]`` (at most ``nodes_per_hole`` of its
    candidates, spread out in travel time, fewer when the holes times that exceed
    ``max_nodes``: the cost matrix is dense). :meth:`learn` replaces estimated
    costs by measured ones (e.g. a segment that needed a detour around an
    obstacle) and :meth:`solve` can warm-start from a previous tour.
    """

    def __init__(
        self,
        home_q: NDArray[np.float64],
        candidates: Sequence[NDArray[np.float64]],
        limits: JointLimits,
        nodes_per_hole: int = 16,
        method: str = "lns",
        max_nodes: int = 4000,
        positions_m: NDArray[np.float64] | None = None,
        helper: Helper | None = None,
    ) -> None:
        """``helper`` (:mod:`planner.helper`): chooses half of the holes' representatives and
        builds half of the cost matrix (:mod:`planner.shared_costs`)."""
        if method not in SEQUENCERS:
            raise PlanningError(
                f"unknown sequencing method {method!r} (use one of {', '.join(SEQUENCERS)})"
            )
        if not candidates or any(len(c) == 0 for c in candidates):
            raise PlanningError("the sequencer needs holes, each with a candidate configuration")
        self.method = method
        self.home = np.asarray(home_q, dtype=float)
        self.candidates = [np.asarray(c, dtype=float) for c in candidates]
        k = max(min(nodes_per_hole, max_nodes // len(self.candidates)), min(nodes_per_hole, 4))
        self.reps = every_representatives(self.candidates, k, self.home, limits, helper)
        stacked = [c[r] for c, r in zip(self.candidates, self.reps, strict=True)]
        self.nodes = np.vstack([self.home[None, :], *stacked])
        self.owner = np.concatenate([[-1]] + [np.full(len(r), h) for h, r in enumerate(self.reps)])
        self.local = np.concatenate([[-1]] + [np.asarray(r) for r in self.reps]).astype(np.int64)
        offsets = np.cumsum([1] + [len(r) for r in self.reps])
        self.groups = [np.arange(offsets[h], offsets[h] + len(r)) for h, r in enumerate(self.reps)]
        table = cost_table(
            limits.velocity, limits.acceleration, limits.jerk, limits.upper - limits.lower
        )
        self.G, held = symmetric_costs(table, self.nodes, helper)
        #: the matrix the helper holds (planner.shared_costs.held_matrix), while it is ``G``
        self.helper_G = self.G if held else None
        self.table = table
        self.positions_m = None if positions_m is None else np.asarray(positions_m, float)
        self.task_order: list[int] | None = None  # add_task_space_nodes
        self._node_of = {
            (int(h), int(k)): v for v, (h, k) in enumerate(zip(self.owner, self.local, strict=True))
        }
        self.lim = (limits.velocity, limits.acceleration, limits.jerk)
        self.learned: dict[tuple[int, int], float] = {}
        self._near: NDArray[np.int64] | None = None  # planner.lns.near_holes, made once

    def near_holes(self) -> NDArray[np.int64]:
        """Row h: the holes nearest hole h (:func:`planner.lns.near_holes`), made once, from
        the costs of the first call (a neighbour list only guides which moves are tried)."""
        if self._near is None:
            self._near = near_holes(self.G, self.groups)
        return self._near

    def add_nodes(self, picks: Sequence[tuple[int, int]]) -> list[int]:
        """Node ids of hole candidates ``(hole, row)``; those not yet nodes join their hole's
        group (costs from the lookup table, as every node's)."""
        if len(self.candidates) > NEAR_ABOVE:
            self.near_holes()  # made from the contiguous groups, before they grow
        new = list(dict.fromkeys(p for p in picks if p not in self._node_of))
        if new:
            N, m = len(self.nodes), len(new)
            q = np.array([self.candidates[h][k] for h, k in new])
            self.nodes = np.vstack([self.nodes, q])
            G = np.empty((N + m, N + m))
            G[:N, :N] = self.G
            G[N:, :] = self.table.matrix(q, self.nodes)
            G[:N, N:] = self.table.matrix(self.nodes[:N], q)
            self.G = G
            self.owner = np.concatenate([self.owner, [h for h, _ in new]])
            self.local = np.concatenate([self.local, [k for _, k in new]]).astype(np.int64)
            for i, (h, k) in enumerate(new):
                self._node_of[(h, k)] = N + i
                self.groups[h] = np.append(self.groups[h], N + i)
        return [self._node_of[p] for p in picks]

    def every_candidate(self, order: Sequence[int]) -> list[int]:
        """Nodes of the best configuration per hole among *every* candidate for ``order``
        (:func:`planner.full_choice.layered_choice`), added as nodes where needed."""
        rows, _ = layered_choice(self.table, self.home, [self.candidates[h] for h in order])
        return self.add_nodes([(int(h), r) for h, r in zip(order, rows, strict=True)])

    def add_task_space_nodes(self) -> None:
        """Up to ``POLISH_MAX_HOLES`` holes, with viewpoint positions: the configurations of
        the task-space start (:func:`planner.full_choice.task_space_order`, every candidate)
        join the nodes."""
        n = len(self.candidates)
        if self.method == "lns" and self.positions_m is not None and n <= POLISH_MAX_HOLES:
            self.task_order = task_space_order(self.positions_m)
            self.every_candidate(self.task_order)

    def learn(self, costs: dict[tuple[int, int], float]) -> None:
        """Set measured costs (s) for node pairs, both directions."""
        for (u, v), c in costs.items():
            self.G[u, v] = self.G[v, u] = c
            self.learned[(u, v)] = self.learned[(v, u)] = c

    def cost_of(self, visited: Sequence[int]) -> float:
        """Cost (s) of visiting ``visited`` nodes in order from home back to home.

        Exact rest-to-rest durations, except where a measured cost was learned.
        """
        path = [0, *visited, 0]
        Q = self.nodes[path]
        edges = travel_time(Q[:-1], Q[1:], *self.lim)
        for k in range(len(path) - 1):
            edges[k] = self.learned.get((path[k], path[k + 1]), edges[k])
        return float(edges.sum())

    def _polish(
        self,
        visited: list[int],
        settings: LnsSettings,
        budget_s: float,
        seed: int,
        record: list[list[int]] | None,
    ) -> tuple[list[int], bool]:
        """Every candidate for the found order, and the task-space start (module
        :mod:`planner.full_choice`); returns the best tour's nodes and whether the time cap
        bound."""
        best, best_cost, hit = list(visited), self.cost_of(visited), False
        starts = [[int(self.owner[v]) for v in visited]]
        if self.task_order is not None:
            starts.append(list(self.task_order))
        div = {True: POLISH_WORK[0], False: POLISH_WORK[1]}
        for k, order in enumerate(starts):
            for r in range(POLISH_ROUNDS):
                tour = self.every_candidate(order)
                s = LnsSettings(
                    max_iterations=settings.max_iterations // div[r == 0 and k > 0],
                    patience=settings.patience // div[r == 0 and k > 0],
                    time_limit_s=budget_s,  # thread CPU time: binds on a crawling machine only
                )
                start = [int(self.owner[v]) for v in tour]
                near = self.near_holes() if len(self.groups) > NEAR_ABOVE else None
                found = GtspLns(self.G, self.groups, seed + 1 + r, record, near).run(s, start)
                hit = hit or found.hit_time_limit
                cost = self.cost_of(found.nodes)
                if not cost < best_cost - 1e-9:
                    break
                best, best_cost, order = list(found.nodes), cost, list(found.order)
        return best, hit

    def solve(
        self,
        time_budget_s: float,
        seed: int,
        effort: float = 1.0,
        warm: Sequence[int] | None = None,
        repair: bool = False,
        record: list[list[int]] | None = None,
    ) -> SequenceResult:
        """Search a tour; ``warm`` (visited nodes) seeds the LNS instead of its greedy start.

        ``repair`` (with ``warm``): a short search that mends a tour after some of its
        costs changed (work 20 + n/10 iterations, scaled by ``effort``). ``record``: the
        LNS appends the node lists of the tours it accepted (:mod:`planner.lns`); the other
        methods leave it empty.
        """
        started = time.perf_counter()
        n = len(self.candidates)
        if self.method == "lns":
            short = repair and warm is not None
            settings = LnsSettings(
                max_iterations=int(effort * ((20 + n // 10) if short else (200 + 4 * n))),
                patience=int(effort * ((10 + n // 20) if short else (50 + n))),
                time_limit_s=time_budget_s,
            )
            start = None if warm is None else [int(self.owner[v]) for v in warm]
            near = self.near_holes() if n > NEAR_ABOVE else None
            found = GtspLns(self.G, self.groups, seed, record, near).run(settings, start)
            visited, hit = found.nodes, found.hit_time_limit
            if not short and n <= POLISH_MAX_HOLES:
                visited, hit2 = self._polish(visited, settings, time_budget_s, seed, record)
                hit = hit or hit2
        elif self.method == "pyvrp":
            base, per_hole = PYVRP_ITERATIONS
            its = effort * (base + per_hole * n) * (0.2 if repair and warm is not None else 1.0)
            visited, hit = solve_gtsp_pyvrp(
                self.G, self.groups, int(its), time_budget_s, seed, warm
            )
        else:
            limit = int(effort * (200 + 5 * n))
            visited, hit = solve_gtsp(self.G, self.groups, time_budget_s, limit, seed)
        if warm is not None and self.cost_of(warm) <= self.cost_of(visited):
            visited = list(warm)
        order = [int(self.owner[v]) for v in visited]
        choice = [int(self.local[v]) for v in visited]
        return SequenceResult(
            order, choice, self.cost_of(visited), time.perf_counter() - started, hit, list(visited)
        )


def sequence(
    home_q: NDArray[np.float64],
    candidates: Sequence[NDArray[np.float64]],
    limits: JointLimits,
    time_budget_s: float,
    seed: int,
    nodes_per_hole: int = 16,
    effort: float = 1.0,
    method: str = "lns",
) -> SequenceResult:
    """Order the holes and choose one configuration each, in one solve (see module docstring).

    ``candidates[h]`` holds hole h's collision-free configurations (k_h, dof), rad.
    ``method`` is ``"lns"`` (:mod:`planner.lns`, the default) or ``"ortools"``
    (routing with one disjunction per hole). ``effort`` scales the search work.
    """
    if not candidates:
        return SequenceResult([], [], 0.0, 0.0, False, [])
    sequencer = GtspSequencer(home_q, candidates, limits, nodes_per_hole, method)
    return sequencer.solve(time_budget_s, seed, effort)
