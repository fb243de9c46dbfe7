"""The inner loops of the GTSP search (:mod:`planner.lns`), compiled by Numba.

Every full-scan function here is the scalar form of a numpy expression of the search
(:mod:`planner.lns` and :mod:`planner.local_search`, which run up to 60 holes): the
same arithmetic in the same order, and ties broken the same way (the first minimum in
row-major order, as ``np.argmin``), so the tours are the same, bit for bit. What
changes is the cost: no temporary matrices and no Python loop over the tour's layers.

``G`` is the cost matrix (s) of the search's nodes, ``path`` a node list with home
(node 0) at both ends; a hole's nodes are ``gnodes[goff[h]:goff[h + 1]]``.

Compiled on first use and cached beside this file (``cache=True``): a fresh process
loads the machine code instead of compiling again. The move deltas and appliers are
shared with the neighbour moves of large tours (:mod:`planner.lns_near`); every kernel of
both is compiled up front by :func:`planner.lns_compile.compile_kernels`.
"""

from __future__ import annotations

import numpy as np
from numba import njit
from numpy.typing import NDArray

#: a move must improve a tour by more than this (s) to be applied (as planner.local_search)
EPS_S = 1e-9


@njit(cache=True)
def two_opt_delta(C: NDArray[np.float64], p: NDArray[np.int64], i: int, j: int) -> float:
    """Change (s) of reversing ``p[i+1 .. j]``: edges (i, j) and (i+1, j+1) replace
    (i, i+1) and (j, j+1)."""
    return C[p[i], p[j]] + C[p[i + 1], p[j + 1]] - C[p[i], p[i + 1]] - C[p[j], p[j + 1]]


@njit(cache=True)
def segment_removal(C: NDArray[np.float64], p: NDArray[np.int64], s: int, e: int) -> float:
    """Change (s) of taking the segment ``p[s .. e]`` out (its neighbours joined)."""
    return C[p[s - 1], p[e + 1]] - C[p[s - 1], p[s]] - C[p[e], p[e + 1]]


@njit(cache=True)
def or_opt_delta(
    C: NDArray[np.float64], p: NDArray[np.int64], s: int, e: int, t: int, removal: float
) -> tuple[float, bool]:
    """Change (s) of moving the segment ``p[s .. e]`` (its :func:`segment_removal` given) into the
    edge (t, t+1), the better way round, and whether reversed."""
    base = removal - C[p[t], p[t + 1]]
    fwd = C[p[s], p[t]] + C[p[e], p[t + 1]] + base
    rev = C[p[e], p[t]] + C[p[s], p[t + 1]] + base
    return min(fwd, rev), rev < fwd


@njit(cache=True)
def _two_opt(C: NDArray[np.float64], p: NDArray[np.int64]) -> tuple[float, int, int]:
    """Best 2-opt move on the path ``p`` of ``C``: reverse ``p[i+1 .. j]`` (delta_s, i, j)."""
    m = p.shape[0] - 1
    best, bi, bj = np.inf, 0, 0
    for i in range(m):
        for j in range(i + 2, m):
            d = two_opt_delta(C, p, i, j)
            if d < best:
                best, bi, bj = d, i, j
    return best, bi, bj


@njit(cache=True)
def _or_opt(
    C: NDArray[np.float64], p: NDArray[np.int64], length: int
) -> tuple[float, int, int, bool]:
    """Best move of the segment ``p[i .. i+length-1]`` to the edge (j, j+1), maybe reversed
    (delta_s, i, j, reversed); home ends never move."""
    m = p.shape[0] - 1
    if m - length < 1 or m < 2:
        return np.inf, 0, 0, False
    best, bs, bj, brev = np.inf, 1, 0, False
    for s in range(1, m - length + 1):
        e = s + length - 1
        removal = segment_removal(C, p, s, e)
        for j in range(m):
            if s - 1 <= j <= e:
                continue
            d, rev = or_opt_delta(C, p, s, e, j, removal)
            if d < best:
                best, bs, bj, brev = d, s, j, rev
    return best, bs, bj, brev


@njit(cache=True)
def apply_move(
    p: NDArray[np.int64], kind: int, i: int, j: int, length: int, rev: bool
) -> NDArray[np.int64]:
    """``p`` after a 2-opt move (kind 0: reverse ``p[i+1 .. j]``) or an or-opt move (kind 1:
    ``p[i .. i+length-1]``, maybe reversed, to between positions j and j+1)."""
    if kind == 0:
        p[i + 1 : j + 1] = p[i + 1 : j + 1][::-1].copy()
        return p
    seg = p[i : i + length].copy()
    if rev:
        seg = seg[::-1].copy()
    rest = np.concatenate((p[:i], p[i + length :]))
    at = j + 1 if j < i else j + 1 - length
    return np.concatenate((rest[:at], seg, rest[at:]))


@njit(cache=True)
def insert_at(
    o: NDArray[np.int64], v: NDArray[np.int64], k: int, e: int, h: int, node: int
) -> None:
    """Insert hole ``h`` with ``node`` at position ``e`` of the first ``k`` entries."""
    o[e + 1 : k + 1] = o[e:k].copy()
    v[e + 1 : k + 1] = v[e:k].copy()
    o[e] = h
    v[e] = node


@njit(cache=True)
def improve_path(
    G: NDArray[np.float64], path: NDArray[np.int64], max_moves: int
) -> NDArray[np.int64]:
    """Local optimum of 2-opt and or-opt (segments of 1-3), best improvement first, from the
    order of ``path`` (home ends stay); returns the permutation of path positions."""
    n = path.shape[0]
    C = np.empty((n, n))
    for a in range(n):
        for b in range(n):
            C[a, b] = G[path[a], path[b]]
    p = np.arange(n)
    for _ in range(max_moves):
        d, i, j = _two_opt(C, p)
        kind, length, rev = 0, 0, False
        for ln in (1, 2, 3):
            d2, i2, j2, r2 = _or_opt(C, p, ln)
            if d2 < d:
                d, i, j, kind, length, rev = d2, i2, j2, 1, ln, r2
        if not d < -EPS_S:
            break
        p = apply_move(p, kind, i, j, length, rev)
    return p


@njit(cache=True)
def _is_span(gnodes: NDArray[np.int64], b0: int, kb: int) -> bool:
    """True when ``gnodes[b0 : b0 + kb]`` are consecutive node ids (a hole's first nodes
    are; nodes added later to a hole's group are not)."""
    for b in range(1, kb):  # noqa: SIM110 (a plain loop: compiled by Numba)
        if gnodes[b0 + b] != gnodes[b0] + b:
            return False
    return True


@njit(cache=True)
def layered(
    G: NDArray[np.float64],
    order: NDArray[np.int64],
    gnodes: NDArray[np.int64],
    goff: NDArray[np.int64],
) -> tuple[NDArray[np.int64], float]:
    """Exact best node per hole for the hole ``order``, home at both ends (layered shortest
    path); returns the nodes and the tour cost (s)."""
    n = order.shape[0]
    out = np.empty(n, dtype=np.int64)
    if n == 0:
        return out, 0.0
    kmax = 0
    for h in order:
        kmax = max(kmax, goff[h + 1] - goff[h])
    back = np.zeros((n, kmax), dtype=np.int64)
    a0 = goff[order[0]]
    ka = goff[order[0] + 1] - a0
    dist = np.empty(kmax)
    for a in range(ka):
        dist[a] = G[0, gnodes[a0 + a]]
    new = np.empty(kmax)
    for li in range(1, n):
        b0 = goff[order[li]]
        kb = goff[order[li] + 1] - b0
        new[:kb] = np.inf
        bk = back[li]
        bk[:kb] = 0
        c0 = gnodes[b0]
        if _is_span(gnodes, b0, kb):  # the hole's nodes are columns c0 .. c0+kb-1 of G
            for a in range(ka):  # a contiguous slice of a row: the inner loop vectorises
                row = G[gnodes[a0 + a], c0 : c0 + kb]
                da = dist[a]
                for b in range(kb):
                    t = da + row[b]
                    if t < new[b]:
                        new[b] = t
                        bk[b] = a
        else:
            for a in range(ka):  # rows of G, read along: the first a with the least total wins
                r = gnodes[a0 + a]
                da = dist[a]
                for b in range(kb):
                    t = da + G[r, gnodes[b0 + b]]
                    if t < new[b]:
                        new[b] = t
                        bk[b] = a
        dist[:kb] = new[:kb]
        a0, ka = b0, kb
    best, pick = np.inf, 0
    for a in range(ka):
        t = dist[a] + G[gnodes[a0 + a], 0]
        if t < best:
            best, pick = t, a
    for li in range(n - 1, -1, -1):
        out[li] = gnodes[goff[order[li]] + pick]
        pick = back[li, pick]
    return out, best


@njit(cache=True)
def insert(
    G: NDArray[np.float64],
    order: NDArray[np.int64],
    nodes: NDArray[np.int64],
    removed: NDArray[np.int64],
    gnodes: NDArray[np.int64],
    goff: NDArray[np.int64],
) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """Insert each ``removed`` hole, in turn, at its cheapest position with its cheapest
    node; returns the hole order and the nodes."""
    n = order.shape[0] + removed.shape[0]
    o = np.empty(n, dtype=np.int64)
    v = np.empty(n, dtype=np.int64)
    k = order.shape[0]
    o[:k] = order
    v[:k] = nodes
    for h in removed:
        best, be, bc = np.inf, 0, 0
        for e in range(k + 1):
            a = 0 if e == 0 else v[e - 1]
            b = 0 if e == k else v[e]
            edge = G[a, b]
            for c in range(goff[h], goff[h + 1]):
                x = G[a, gnodes[c]] + G[gnodes[c], b] - edge
                if x < best:
                    best, be, bc = x, e, c
        insert_at(o, v, k, be, h, gnodes[bc])
        k += 1
    return o, v
