"""GLNS-style large-neighbourhood search for the generalised TSP.

Nodes ``0..N-1`` with node 0 the home depot; ``groups[h]`` lists hole h's nodes
(candidate configurations); ``G[a, b]`` is the travel time (s) from node a to b.
A tour visits one node per group, from home back to home.

Each iteration removes some holes (random ones, or those nearest a random hole
in travel time), reinserts each at its cheapest position with its cheapest
node, improves the order by 2-opt/or-opt with nodes fixed, and re-chooses the
node of every hole exactly for the new order (layered shortest path). A new
tour replaces the current one when it is not worse by more than a threshold
that shrinks to zero; the best tour is returned.

``record`` (optional): every tour the search accepts (as its current or best tour) is
appended to it as its node list, so that a caller checking motions lazily can check the
motions of the tours the search is heading for in one batch, not one tour at a time.

Determinism: all randomness comes from ``numpy.random.default_rng(seed)``; the
search stops after ``max_iterations`` or after ``patience`` iterations without
a new best, whichever comes first. ``time_limit_s`` is a hard cap on the thread's CPU
time (so that other jobs on a shared machine do not shorten the search) that only binds
on a slow machine (then the result is reported as such).
"""

from __future__ import annotations

import itertools
import time
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from planner.local_search import improve_order

#: at most this many moves per local optimisation (a bound that a tour never reaches)
MAX_MOVES = 10_000
#: above this many holes the search's loops run compiled (:mod:`planner.lns_kernel`; the
#: same numbers as the numpy code here, bit for bit), below it Numba's ~1 s of loading
#: per process costs more than it saves (the frame: 41 holes)
COMPILED_ABOVE = 60
#: above this many holes, moves and insertions only join a hole to one of its ``NEAR_K``
#: nearest holes (:mod:`planner.lns_near`); up to it, every move is scanned
NEAR_ABOVE = 120
NEAR_K = 8


def near_holes(
    G: NDArray[np.floating], groups: Sequence[NDArray[np.int64]], k: int = NEAR_K
) -> NDArray[np.int64]:
    """Row h: the ``k`` holes nearest hole h (least travel time between their nodes, s),
    nearest first (ties: lower index); ``groups`` must be contiguous ranges in order."""
    starts = np.array([g[0] for g in groups], dtype=np.int64)
    # along the rows first (contiguous), then the small (nodes, holes) result: a third of the
    # time of the columns first, the same minima
    D = np.minimum.reduceat(np.minimum.reduceat(G[1:, 1:], starts - 1, axis=1), starts - 1, axis=0)
    np.fill_diagonal(D, np.inf)
    return np.argsort(D, axis=1, kind="stable")[:, : min(k, len(groups) - 1)].astype(np.int64)


@dataclass(frozen=True)
class LnsSettings:
    """Work limits of the search (see module docstring)."""

    max_iterations: int
    patience: int
    time_limit_s: float
    max_removed: int = 25
    start_threshold: float = 0.003


@dataclass(frozen=True)
class LnsResult:
    """Best tour: the hole order and the node visited for each, its cost (s), search facts."""

    order: list[int]
    nodes: list[int]
    cost_s: float
    iterations: int
    hit_time_limit: bool


def layered_nodes(
    G: NDArray[np.floating],
    layers: Sequence[NDArray[np.int64]],
    spans: Sequence[tuple[int, int]] | None = None,
) -> tuple[list[int], float]:
    """Exact best node per layer for a fixed order of layers, home (node 0) at both ends.

    ``spans`` (optional): ``(first, end)`` of each layer when it is the contiguous range
    ``first .. end-1`` of nodes (then the blocks of ``G`` are read as views, not copies:
    the same numbers, a third of the time)."""
    if not layers:
        return [], 0.0
    blocks = (
        [G[a0:a1, b0:b1] for (a0, a1), (b0, b1) in itertools.pairwise(spans)]
        if spans is not None
        else [G[prev[:, None], cur[None, :]] for prev, cur in itertools.pairwise(layers)]
    )
    dist = G[0, layers[0]].astype(float)
    back = []
    for block in blocks:
        total = dist[:, None] + block
        back.append(np.argmin(total, axis=0))
        dist = total.min(axis=0)
    total = dist + G[layers[-1], 0]
    pick = [int(np.argmin(total))]
    cost = float(total[pick[0]])
    for arg in reversed(back):
        pick.append(int(arg[pick[-1]]))
    pick.reverse()
    return [int(layer[p]) for layer, p in zip(layers, pick, strict=True)], cost


def _span(group: NDArray[np.int64]) -> tuple[int, int] | None:
    """``(first, end)`` when ``group`` is the range ``first .. end-1``, else None."""
    if len(group) and np.array_equal(group, np.arange(group[0], group[0] + len(group))):
        return int(group[0]), int(group[0]) + len(group)
    return None


class GtspLns:
    """The search over one problem instance (see module docstring)."""

    def __init__(
        self,
        G: NDArray[np.floating],
        groups: Sequence[NDArray[np.int64]],
        seed: int,
        record: list[list[int]] | None = None,
        near: NDArray[np.int64] | None = None,
        compiled: bool | None = None,
    ) -> None:
        """``near``: :func:`near_holes` of ``G`` (made here when needed and not given);
        ``compiled``: run the compiled loops (default: above ``COMPILED_ABOVE`` holes)."""
        self.G = G
        self.groups = [np.asarray(g, dtype=np.int64) for g in groups]
        self.rng = np.random.default_rng(seed)
        self.record = record
        self.k = None
        self.near = None
        if len(self.groups) > COMPILED_ABOVE if compiled is None else compiled:
            from planner import lns_kernel, lns_near  # Numba: loaded only where it pays

            self.k = lns_kernel
            self.kn = lns_near
            self.G = np.ascontiguousarray(G, dtype=np.float64)  # no copy of the planner's
            self.gnodes = np.concatenate([np.zeros(0, dtype=np.int64), *self.groups])
            self.goff = np.cumsum([0] + [len(g) for g in self.groups]).astype(np.int64)
            if len(self.groups) > NEAR_ABOVE:
                self.near = near_holes(self.G, self.groups) if near is None else near
        spans = [_span(g) for g in self.groups]
        self.spans: list[tuple[int, int]] | None = (
            None if any(s is None for s in spans) else spans  # type: ignore[assignment]
        )

    def _rechoose(self, order: list[int]) -> tuple[list[int], list[int], float]:
        if self.k is not None:
            holes = np.array(order, dtype=np.int64)
            nodes, cost = self.k.layered(self.G, holes, self.gnodes, self.goff)
            return order, nodes.tolist(), float(cost)
        spans = None if self.spans is None else [self.spans[h] for h in order]
        nodes, cost = layered_nodes(self.G, [self.groups[h] for h in order], spans)
        return order, nodes, cost

    def _local(
        self, order: list[int], nodes: list[int], cost: float
    ) -> tuple[list[int], list[int], float]:
        for _ in range(2):
            path = [0, *nodes, 0]
            if self.k is None:
                perm = improve_order(self.G[np.ix_(path, path)].astype(float))
            elif self.near is None:
                perm = self.k.improve_path(self.G, np.array(path), MAX_MOVES).tolist()
            else:
                holes = np.array(order, dtype=np.int64)
                G = np.asarray(self.G, dtype=np.float64)  # compiled: already float64, no copy
                perm = self.kn.improve_path_near(
                    G, np.array(path), holes, self.near, MAX_MOVES
                ).tolist()
            inner = [p - 1 for p in perm[1:-1]]
            o2, n2, c2 = self._rechoose([order[p] for p in inner])
            if not c2 < cost - 1e-9:
                return (o2, n2, c2) if c2 <= cost else (order, nodes, cost)
            order, nodes, cost = o2, n2, c2
        return order, nodes, cost

    def initial(self) -> tuple[list[int], list[int], float]:
        """Greedy nearest-node construction from home, then local improvement."""
        owner = np.full(self.G.shape[0], -1)
        for h, g in enumerate(self.groups):
            owner[g] = h
        open_nodes = np.concatenate(self.groups)
        cur, order = 0, []
        while len(open_nodes):
            nxt = int(open_nodes[np.argmin(self.G[cur, open_nodes])])
            h = int(owner[nxt])
            order.append(h)
            open_nodes = open_nodes[owner[open_nodes] != h]
            cur = nxt
        return self._local(*self._rechoose(order))

    def _remove(
        self, order: list[int], nodes: list[int], k: int
    ) -> tuple[list[int], list[int], list[int]]:
        n = len(order)
        if self.rng.random() < 0.5:
            drop = set(self.rng.choice(n, size=k, replace=False).tolist())
        else:
            center = nodes[int(self.rng.integers(n))]
            d = self.G[center, nodes] + self.G[nodes, center]
            drop = set(np.argsort(d, kind="stable")[:k].tolist())
        keep = [i for i in range(n) if i not in drop]
        removed = [order[i] for i in sorted(drop)]
        self.rng.shuffle(removed)
        return [order[i] for i in keep], [nodes[i] for i in keep], removed

    def _insert(
        self, order: list[int], nodes: list[int], removed: list[int]
    ) -> tuple[list[int], list[int]]:
        """Each removed hole, in turn, at its cheapest position with its cheapest node."""
        if self.k is not None:
            G = np.asarray(self.G, dtype=np.float64)  # compiled: already float64, no copy
            args = (G, np.array(order), np.array(nodes), np.array(removed), self.gnodes, self.goff)
            o, v = (
                self.k.insert(*args) if self.near is None else self.kn.insert_near(*args, self.near)
            )
            return o.tolist(), v.tolist()
        for h in removed:
            path = np.array([0, *nodes, 0])
            cand = self.groups[h]
            if self.spans is not None:  # views of the contiguous columns: the same numbers
                c0, c1 = self.spans[h]
                into, out = self.G[path[:-1], c0:c1], self.G[c0:c1, path[1:]].T
            else:
                into, out = self.G[np.ix_(path[:-1], cand)], self.G[np.ix_(cand, path[1:])].T
            extra = into + out - self.G[path[:-1], path[1:]][:, None]
            e, c = divmod(int(np.argmin(extra)), extra.shape[1])
            order.insert(e, h)
            nodes.insert(e, int(cand[c]))
        return order, nodes

    def _path_cost(self, nodes: list[int]) -> float:
        path = np.array([0, *nodes, 0])
        return float(self.G[path[:-1], path[1:]].sum())

    def run(self, settings: LnsSettings, start: list[int] | None = None) -> LnsResult:
        """Search from ``start`` (a hole order) or the greedy tour; returns the best tour found."""
        if self.k is not None:
            from planner.lns_compile import compile_kernels

            compile_kernels()  # before the clock starts
        started = time.thread_time()
        cur = best = self.initial() if start is None else self._local(*self._rechoose(list(start)))
        n = len(self.groups)
        since_best, hit, iterations = 0, False, 0
        for it in range(settings.max_iterations):
            if n < 3 or since_best >= settings.patience:
                break
            if time.thread_time() - started > settings.time_limit_s:
                hit = True
                break
            iterations = it + 1
            k = int(self.rng.integers(1, max(2, min(settings.max_removed, n // 3)) + 1))
            order, nodes, removed = self._remove(cur[0], cur[1], k)
            order, nodes = self._insert(order, nodes, removed)
            new = self._local(order, nodes, self._path_cost(nodes))
            threshold = settings.start_threshold * best[2] * (1 - it / settings.max_iterations)
            if new[2] < cur[2] + threshold:
                cur = new
                if self.record is not None:
                    self.record.append(list(new[1]))
            if new[2] < best[2] - 1e-9:
                best, since_best = new, 0
            else:
                since_best += 1
        return LnsResult(best[0], best[1], best[2], iterations, hit)
