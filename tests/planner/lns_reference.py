"""The numpy reference of the GTSP search's compiled kernels (:mod:`planner.lns_kernel`).

These are the search's loops as they were written in numpy before they were compiled:
the kernels must give the same numbers, bit for bit (``test_planner_lns_kernel``).

Order improvement with fixed configurations: 2-opt and or-opt, vectorised in numpy.

A tour is the path ``Q = [home, q_1, ..., q_n, home]`` (rad); ``C`` is its matrix of
symmetric travel times (s). Moves keep both home ends in place and are applied
best-improvement first until none improves by more than ``EPS_S``.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from functools import lru_cache

import numpy as np
from numpy.typing import NDArray

EPS_S = 1e-9


@lru_cache(maxsize=64)
def _two_opt_mask(m: int) -> NDArray[np.float64]:
    """0 where the 2-opt move (i, j) is valid (j >= i + 2), inf elsewhere."""
    return np.where(np.triu(np.ones((m, m), dtype=bool), k=2), 0.0, np.inf)


@lru_cache(maxsize=64)
def _or_opt_mask(m: int, length: int) -> NDArray[np.float64]:
    """0 where segment i may go to edge j (j outside [i-1, i+length-1]), inf elsewhere."""
    starts = np.arange(1, m - length + 1)
    j = np.arange(m)
    bad = (j[None, :] >= starts[:, None] - 1) & (j[None, :] <= starts[:, None] + length - 1)
    return np.where(bad, np.inf, 0.0)


def best_two_opt(C: NDArray[np.float64]) -> tuple[float, int, int]:
    """Best 2-opt move on path costs ``C``: reverse ``Q[i+1 .. j]``. Returns (delta_s, i, j)."""
    m = C.shape[0] - 1  # number of edges
    edge = C[np.arange(m), np.arange(1, m + 1)]
    delta = C[:m, :m] + C[1:, 1:] - edge[:, None] - edge[None, :] + _two_opt_mask(m)
    i, j = divmod(int(np.argmin(delta)), m)
    return float(delta[i, j]), i, j


def best_or_opt(C: NDArray[np.float64], length: int) -> tuple[float, int, int, bool]:
    """Best move of a segment ``Q[i .. i+length-1]`` to the edge (j, j+1), maybe reversed.

    ``C`` must be symmetric. Returns (delta_s, i, j, reversed). Home ends never move.
    """
    m = C.shape[0] - 1
    if m - length < 1 or m < 2:
        return np.inf, 0, 0, False
    starts = np.arange(1, m - length + 1)
    ends = starts + length - 1
    removal = C[starts - 1, ends + 1] - C[starts - 1, starts] - C[ends, ends + 1]
    edge = C[np.arange(m), np.arange(1, m + 1)]
    base = removal[:, None] - edge[None, :] + _or_opt_mask(m, length)
    fwd = C[starts, :m] + C[ends, 1:] + base  # j -> start ... end -> j+1
    rev = C[ends, :m] + C[starts, 1:] + base  # j -> end ... start -> j+1
    best = np.minimum(fwd, rev)
    a, b = divmod(int(np.argmin(best)), m)
    return float(best[a, b]), int(starts[a]), int(b), bool(rev[a, b] < fwd[a, b])


def apply_two_opt(perm: list[int], i: int, j: int) -> list[int]:
    """Reverse ``perm[i+1 .. j]``."""
    return perm[: i + 1] + perm[i + 1 : j + 1][::-1] + perm[j + 1 :]


def apply_or_opt(perm: list[int], i: int, length: int, j: int, reverse: bool) -> list[int]:
    """Move ``perm[i .. i+length-1]`` to between positions j and j+1 (of the original)."""
    seg = perm[i : i + length]
    if reverse:
        seg = seg[::-1]
    rest = perm[:i] + perm[i + length :]
    at = j + 1 if j < i else j + 1 - length
    return rest[:at] + seg + rest[at:]


def improve_order(C: NDArray[np.float64], max_moves: int = 10_000) -> list[int]:
    """Local optimum of 2-opt and or-opt (segments of 1-3) from the identity path order.

    Returns the permutation of path positions (0 and last stay in place).
    """
    perm = list(range(C.shape[0]))
    cur = C
    for _ in range(max_moves):
        moves: list[tuple[float, str, tuple[int, ...]]] = []
        d, i, j = best_two_opt(cur)
        moves.append((d, "2opt", (i, j)))
        for length in (1, 2, 3):
            d, i, j, rev = best_or_opt(cur, length)
            moves.append((d, "oropt", (i, length, j, int(rev))))
        d, kind, args = min(moves, key=lambda mv: mv[0])
        if not d < -EPS_S:
            break
        step = list(range(cur.shape[0]))
        if kind == "2opt":
            step = apply_two_opt(step, *args)
        else:
            i, length, j, rev = args
            step = apply_or_opt(step, i, length, j, bool(rev))
        perm = [perm[s] for s in step]
        cur = cur[np.ix_(step, step)]
    return perm


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


def insert_reference(
    G: NDArray[np.floating],
    order: list[int],
    nodes: list[int],
    removed: list[int],
    groups: Sequence[NDArray[np.int64]],
) -> tuple[list[int], list[int]]:
    """Each removed hole, in turn, at its cheapest position with its cheapest node."""
    order, nodes = list(order), list(nodes)
    for h in removed:
        path = np.array([0, *nodes, 0])
        cand = groups[h]
        into, out = G[np.ix_(path[:-1], cand)], G[np.ix_(cand, path[1:])].T
        extra = into + out - G[path[:-1], path[1:]][:, None]
        e, c = divmod(int(np.argmin(extra)), extra.shape[1])
        order.insert(e, h)
        nodes.insert(e, int(cand[c]))
    return order, nodes
