"""A roadmap among the candidate configurations: obstacle-aware costs for the GTSP.

Before the first solve, the straight motions between every node (home and each
hole's candidate configurations) and its ``k`` nearest nodes of other holes (in
rest-to-rest travel time) are checked in one batch (:class:`BatchEdgeChecker`).
The free motions form a roadmap: its nodes are collision-free configurations that
any tour may pass, its edges straight motions known to be free. A motion that
collides gets, as its cost, the shortest path through the roadmap (Dijkstra over
the free edges, weighted by rest-to-rest travel time: a detour with a stop at each
intermediate configuration, an upper bound on the flown detour), and that path is
kept as the segment's first path to try before OMPL. Colliding motions with no
roadmap path keep the estimate ``DETOUR_FACTOR × straight + DETOUR_EXTRA_S``.

Everything here is deterministic: the costs the sequencer sees, and the detours it
is offered, do not depend on the seed or on which edges a random search visited.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import partial

import numpy as np
from numpy.typing import NDArray
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import dijkstra

from planner.edge_check import BatchEdgeChecker
from planner.helper import Helper
from planner.shared_costs import held_matrix

#: estimated duration of a colliding straight motion without a roadmap detour: factor, extra s
DETOUR_FACTOR = 1.5
DETOUR_EXTRA_S = 0.3


@dataclass
class Roadmap:
    """Checked motions between candidate nodes and the detours through the free ones."""

    free: dict[tuple[int, int], bool] = field(default_factory=dict)
    detours: dict[tuple[int, int], list[int]] = field(default_factory=dict)
    checked: int = 0
    #: the free motions as index arrays, made on the first detour query: (entries, u, v)
    _edges: tuple[int, NDArray[np.int64], NDArray[np.int64]] | None = field(
        default=None, repr=False, compare=False
    )
    #: Dijkstra rows (distances s, predecessors) by source node, valid for the edge weights
    #: ``_weights`` (a start's learned costs rarely touch a free motion); not pickled
    _rows: dict[int, tuple[NDArray[np.float64], NDArray[np.int32]]] = field(
        default_factory=dict, repr=False, compare=False
    )
    _weights: NDArray[np.float64] | None = field(default=None, repr=False, compare=False)

    def __getstate__(self) -> dict[str, object]:
        return self.__dict__ | {"_rows": {}, "_weights": None}

    def shortest_from(
        self, G: NDArray[np.float64], sources: list[int]
    ) -> list[tuple[NDArray[np.float64], NDArray[np.int32]]] | None:
        """Dijkstra's distances (s) and predecessors from each of ``sources`` over the free
        motions weighted by the current ``G`` (None: no free motion). Rows already computed
        for the same weights are reused (the same numbers: a row depends on its source and
        the weights only)."""
        u, v, weights = self.free_edges(G)
        if not len(u):
            return None
        grown = any(len(row[0]) != G.shape[0] for row in self._rows.values())  # nodes added
        if self._weights is None or grown or not np.array_equal(self._weights, weights):
            self._rows, self._weights = {}, weights
        todo = [s for s in sources if s not in self._rows]
        if todo:
            N = G.shape[0]
            graph = csr_matrix((weights, (u, v)), shape=(N, N))
            dist, pred = dijkstra(graph, directed=False, indices=todo, return_predecessors=True)
            self._rows.update(zip(todo, zip(dist, pred, strict=True), strict=True))
        return [self._rows[s] for s in sources]

    def free_edges(
        self, G: NDArray[np.float64]
    ) -> tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.float64]]:
        """The free motions ``u``-``v`` and their weights in Dijkstra's graph (s: ``G``'s,
        above 0)."""
        if self._edges is None or self._edges[0] != len(self.free):
            e = np.array([uv for uv, f in self.free.items() if f], dtype=np.int64).reshape(-1, 2)
            self._edges = (len(self.free), e[:, 0], e[:, 1])
            self._weights = None
        _, u, v = self._edges
        return u, v, np.maximum(G[u, v], 1e-9)

    def via(self, u: int, v: int) -> list[int] | None:
        """Intermediate nodes of the roadmap detour from ``u`` to ``v`` (None: none known)."""
        path = self.detours.get((u, v))
        if path is None and (v, u) in self.detours:
            path = self.detours[(v, u)][::-1]
        return path


#: rows per block of :func:`neighbour_pairs` (the same rows as the whole matrix at once)
NEIGHBOUR_BLOCK = 256


def _near_rows(
    G: NDArray[np.float64], owner: NDArray[np.int64], k: int, r0: int, r1: int
) -> tuple[NDArray[np.int64], NDArray[np.float64]]:
    """Rows ``r0:r1`` of :func:`neighbour_pairs`' lists: the ``k`` nearest nodes of other
    holes of each node, and their costs (s, inf where fewer)."""
    near = np.zeros((r1 - r0, k), dtype=np.int64)
    nearest = np.zeros((r1 - r0, k))
    for b0 in range(r0, r1, NEIGHBOUR_BLOCK):  # row blocks: cache-friendly
        b1 = min(b0 + NEIGHBOUR_BLOCK, r1)
        D = np.minimum(G[b0:b1], G[:, b0:b1].T)
        D[owner[b0:b1, None] == owner[None, :]] = np.inf  # same hole (and home with itself)
        part = np.argpartition(D, k - 1, axis=1)[:, :k]
        near[b0 - r0 : b1 - r0] = part
        nearest[b0 - r0 : b1 - r0] = np.take_along_axis(D, part, axis=1)
    return near, nearest


def near_rows_of_held(
    owner: NDArray[np.int64], k: int, r0: int
) -> tuple[NDArray[np.int64], NDArray[np.float64]] | None:
    """In the helper: :func:`_near_rows` from ``r0`` to the end of its held cost matrix
    (:func:`planner.shared_costs.held_matrix`; None: it holds none of that size)."""
    G = held_matrix()
    if G is None or G.shape[0] != len(owner):
        return None
    return _near_rows(G, owner, k, r0, G.shape[0])


def neighbour_pairs(
    G: NDArray[np.float64], owner: NDArray[np.int64], k: int, helper: Helper | None = None
) -> np.ndarray:
    """Undirected pairs (u < v) joining each node to its ``k`` nearest nodes of other holes.

    ``helper``: a helper holding ``G`` (:func:`planner.shared_costs.held_matrix`) makes the
    lists of the second half of the rows (the same lists)."""
    N = G.shape[0]
    k = max(min(k, N - 1), 0)
    if k == 0:
        return np.zeros((0, 2), dtype=np.int64)
    half = (N // 2) // NEIGHBOUR_BLOCK * NEIGHBOUR_BLOCK if helper is not None else N
    theirs = helper.submit(near_rows_of_held, owner, k, half) if helper and half else None
    if theirs is None:
        half = N
    mine = _near_rows(G, owner, k, 0, half)
    if theirs is not None:
        got = Helper.result(theirs, lambda: None)
        rest = _near_rows(G, owner, k, half, N) if got is None else got
        mine = (np.vstack([mine[0], rest[0]]), np.vstack([mine[1], rest[1]]))
    near, nearest = mine
    u = np.repeat(np.arange(N), near.shape[1])
    v = near.ravel()
    ok = np.isfinite(nearest.ravel())
    pairs = np.unique(np.sort(np.column_stack([u[ok], v[ok]]), axis=1), axis=0)
    return pairs


def build_roadmap(
    nodes: NDArray[np.float64],
    G: NDArray[np.float64],
    owner: NDArray[np.int64],
    checker: BatchEdgeChecker,
    k: int,
    helper: Helper | None = None,
    helper_holds_G: bool = False,
) -> Roadmap:
    """Check the ``k``-nearest motions of every node in one batch (see module docstring),
    half of them in the ``helper`` process if given (:mod:`planner.helper`); with
    ``helper_holds_G`` (:func:`planner.shared_costs.held_matrix` is ``G``) half of the
    neighbour lists there too."""
    pairs = neighbour_pairs(G, owner, k, helper if helper_holds_G else None)
    rm = Roadmap()
    if not len(pairs):
        return rm
    ok = checker.free(nodes[pairs[:, 0]], nodes[pairs[:, 1]], helper)
    rm.checked = len(pairs)
    for (u, v), f in zip(pairs.tolist(), ok.tolist(), strict=True):
        rm.free[(u, v)] = f
    return rm


#: with a helper, Dijkstra's sources are shared from this many on (below, one process)
HELPER_MIN_SOURCES = 64


def _walk(pred: NDArray[np.int32], a: int, b: int) -> list[int]:
    """Intermediate nodes of the shortest path ``a`` -> ``b`` from Dijkstra's predecessors."""
    path, x = [], b
    while x != a:
        x = int(pred[x])
        path.append(x)
    return path[::-1][1:]


def _shortest(
    dist_pred: list[tuple[NDArray[np.float64], NDArray[np.int32]]],
    sources: list[int],
    pairs: list[tuple[int, int]],
) -> dict[tuple[int, int], tuple[float, list[int]]]:
    """Distance (s) and intermediate nodes of each of ``pairs`` (sources among ``sources``,
    whose Dijkstra rows ``dist_pred`` are) that the roadmap joins."""
    row = dict(zip(sources, dist_pred, strict=True))
    out = {}
    for a, b in pairs:
        dist, pred = row[a]
        if np.isfinite(dist[b]):
            out[(a, b)] = (float(dist[b]), _walk(pred, a, b))
    return out


def detours_in_helper(
    u: NDArray[np.int64], v: NDArray[np.int64], weights: NDArray[np.float64], n: int,
    sources: list[int], pairs: list[tuple[int, int]],
) -> dict[tuple[int, int], tuple[float, list[int]]]:  # fmt: skip
    """In the helper: :func:`_shortest` of ``pairs`` over the free motions ``u``-``v`` of
    ``weights`` (s) among ``n`` nodes (the same Dijkstra call as :meth:`Roadmap.shortest_from`:
    each row depends on its source and the weights only)."""
    graph = csr_matrix((weights, (u, v)), shape=(n, n))
    dist, pred = dijkstra(graph, directed=False, indices=sources, return_predecessors=True)
    return _shortest(list(zip(dist, pred, strict=True)), sources, pairs)


def detour_costs(
    rm: Roadmap,
    G: NDArray[np.float64],
    blocked: list[tuple[int, int]],
    helper: Helper | None = None,
) -> dict[tuple[int, int], float]:
    """Costs (s) of the ``blocked`` motions: shortest roadmap path, else the estimate.

    Records each detour's intermediate nodes in ``rm.detours``. ``helper``: Dijkstra from
    every other source runs there meanwhile (the same paths; their rows are not kept here).
    """
    if not blocked:
        return {}
    uv = np.array(blocked, dtype=np.int64).reshape(-1, 2)
    u, v = uv[:, 0], uv[:, 1]
    cost = DETOUR_FACTOR * G[u, v] + DETOUR_EXTRA_S
    pairs = [(a, b) for a, b in uv.tolist()]
    sources = sorted(set(u.tolist()))
    remote = None
    if helper is not None and len(sources) >= HELPER_MIN_SOURCES:
        eu, ev, weights = rm.free_edges(G)
        if len(eu):
            there = sources[1::2]
            sources = sources[0::2]
            mine = set(sources)
            theirs = [p for p in pairs if p[0] not in mine]
            pairs = [p for p in pairs if p[0] in mine]
            args = (eu, ev, weights, G.shape[0], there, theirs)
            remote = (helper.submit(detours_in_helper, *args), partial(detours_in_helper, *args))
    found = rm.shortest_from(G, sources)
    paths = {} if found is None else _shortest(found, sources, pairs)
    if remote is not None:
        paths |= Helper.result(*remote)
    for i, (a, b) in enumerate(uv.tolist()):
        got = paths.get((a, b))
        if got is not None:
            cost[i] = max(got[0], float(G[a, b]))
            rm.detours[(a, b)] = got[1]
    return {(a, b): c for (a, b), c in zip(uv.tolist(), cost.tolist(), strict=True)}
