"""The search's compiled loops for large tours (above ``planner.lns.NEAR_ABOVE`` holes):
moves between neighbouring holes only.

A full scan of every move (:mod:`planner.lns_kernel`) costs O(n²) per move and finds
little that the neighbour moves miss (the standard candidate-list technique of TSP local
search): the moves here only join a hole to one of its ``K`` nearest holes (``near[h]``,
hole indices), in O(n K) per move. ``order`` is the hole order of ``path`` (``path[1 + i]``
is a node of hole ``order[i]``). Compiled and cached like :mod:`planner.lns_kernel`
(:func:`planner.lns_compile.compile_kernels` loads both).
"""

from __future__ import annotations

import numpy as np
from numba import njit
from numpy.typing import NDArray

from planner.lns_kernel import (
    EPS_S,
    apply_move,
    insert_at,
    or_opt_delta,
    segment_removal,
    two_opt_delta,
)


@njit(cache=True)
def _positions(p: NDArray[np.int64], order: NDArray[np.int64], holes: int) -> NDArray[np.int64]:
    """Current path position of each hole (-1: not on the path)."""
    pos = np.full(holes, -1, dtype=np.int64)
    for i in range(1, p.shape[0] - 1):
        pos[order[p[i] - 1]] = i
    return pos


@njit(cache=True)
def _best_near_move(
    C: NDArray[np.float64],
    p: NDArray[np.int64],
    pos: NDArray[np.int64],
    i: int,
    near_h: NDArray[np.int64],
) -> tuple[float, int, int, int, int, bool]:
    """The best move joining the hole at position ``i`` to one of ``near_h``: 2-opt moves
    whose new edges include that pair, or-opt moves of a segment ending at ``i`` to either
    side of the neighbour (delta_s, kind 0/1, i, j, length, reversed)."""
    m = p.shape[0] - 1
    best, kind, bi, bj, blen, brev = -EPS_S, -1, 0, 0, 0, False
    for x in near_h:
        j = pos[x]
        if j < 0:
            continue
        a, b = min(i, j), max(i, j)
        if b >= a + 2:  # new edges (a, b) and (a+1, b+1), or (a-1, b-1) and (a, b)
            for s in (a, a - 1):
                t = s + b - a
                if s < 0 or t >= m:
                    continue
                d = two_opt_delta(C, p, s, t)
                if d < best:
                    best, kind, bi, bj = d, 0, s, t
        for length in (1, 2, 3):
            if m - length < 1:
                continue
            for s in (i, i - length + 1):
                e = s + length - 1
                if s < 1 or s > m - length:
                    continue
                removal = segment_removal(C, p, s, e)
                for t in (j - 1, j):
                    if t < 0 or t >= m or s - 1 <= t <= e:
                        continue
                    d, rev = or_opt_delta(C, p, s, e, t, removal)
                    if d < best:
                        best, kind, bi, bj, blen, brev = d, 1, s, t, length, rev
    return best, kind, bi, bj, blen, brev


@njit(cache=True)
def improve_path_near(
    G: NDArray[np.float64],
    path: NDArray[np.int64],
    order: NDArray[np.int64],
    near: NDArray[np.int64],
    max_moves: int,
) -> NDArray[np.int64]:
    """A local optimum of the neighbour moves (:func:`_best_near_move`) from the order of
    ``path``: each hole in a queue (first all, in path order) applies its best improving
    move; the holes at the ends of the edges a move changed join the queue again ("don't
    look bits"). ``G`` must be symmetric. Returns the permutation of path positions."""
    n = path.shape[0]
    p = np.arange(n)
    # the moves read G at the nodes of the current order, v = path[p] (moved with p): the
    # entries of the path's cost matrix C[p[i], p[j]] = G[v[i], v[j]], without building C
    # (n² scattered reads of G per call, most of the call when a tour is near its optimum)
    v = path.copy()
    holes = near.shape[0]
    pos = _positions(p, order, holes)
    queue = np.empty(n - 2 + 6 * max_moves, dtype=np.int64)
    queued = np.zeros(holes, dtype=np.bool_)
    tail = 0
    for i in range(1, n - 1):
        queue[tail] = order[i - 1]
        queued[order[i - 1]] = True
        tail += 1
    head, moves = 0, 0
    while head < tail and moves < max_moves:
        h = queue[head]
        head += 1
        queued[h] = False
        _d, kind, bi, bj, blen, brev = _best_near_move(G, v, pos, pos[h], near[h])
        if kind < 0:
            continue
        moves += 1
        if kind == 0:
            touched = np.array([p[bi], p[bi + 1], p[bj], p[bj + 1]])
        else:
            e = bi + blen - 1
            touched = np.array([p[bi - 1], p[bi], p[e], p[e + 1], p[bj], p[bj + 1]])
        p = apply_move(p, kind, bi, bj, blen, brev)
        v = apply_move(v, kind, bi, bj, blen, brev)
        pos = _positions(p, order, holes)
        for q in touched:
            if 1 <= q <= n - 2 and not queued[order[q - 1]]:
                queue[tail] = order[q - 1]
                queued[order[q - 1]] = True
                tail += 1
    return p


@njit(cache=True)
def insert_near(
    G: NDArray[np.float64],
    order: NDArray[np.int64],
    nodes: NDArray[np.int64],
    removed: NDArray[np.int64],
    gnodes: NDArray[np.int64],
    goff: NDArray[np.int64],
    near: NDArray[np.int64],
) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """:func:`insert` trying only the positions beside a hole's neighbours on the tour
    (every position when none of them is on it). ``G`` must be symmetric."""
    holes = near.shape[0]
    n = order.shape[0] + removed.shape[0]
    o = np.empty(n, dtype=np.int64)
    v = np.empty(n, dtype=np.int64)
    k = order.shape[0]
    o[:k] = order
    v[:k] = nodes
    pos = np.full(holes, -1, dtype=np.int64)
    for i in range(k):
        pos[o[i]] = i
    tried = np.zeros(n + 1, dtype=np.bool_)
    for h in removed:
        best, be, bc = np.inf, -1, 0
        tried[: k + 1] = False
        cands = np.empty(2 * near.shape[1], dtype=np.int64)
        nc = 0
        for x in near[h]:
            q = pos[x]
            if q < 0:
                continue
            for e in (q, q + 1):
                if not tried[e]:
                    tried[e] = True
                    cands[nc] = e
                    nc += 1
        if nc == 0:
            cands = np.arange(k + 1)
            nc = k + 1
        cands[:nc].sort()
        for ci in range(nc):
            e = cands[ci]
            a = 0 if e == 0 else v[e - 1]
            b = 0 if e == k else v[e]
            edge = G[a, b]
            for c in range(goff[h], goff[h + 1]):
                x2 = G[a, gnodes[c]] + G[b, gnodes[c]] - edge
                if x2 < best:
                    best, be, bc = x2, e, c
        insert_at(o, v, k, be, h, gnodes[bc])
        k += 1
        for i in range(be, k):
            pos[o[i]] = i
    return o, v
