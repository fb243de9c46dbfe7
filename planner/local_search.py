"""Order improvement with fixed configurations: 2-opt and or-opt, vectorised in numpy.

A tour is the path ``Q = [home, q_1, ..., q_n, home]`` (rad); ``C`` is its matrix of
symmetric travel times (s). Moves keep both home ends in place and are applied
best-improvement first until none improves by more than ``EPS_S``.
"""

from __future__ import annotations

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
            i, length, j, rev_flag = args
            step = apply_or_opt(step, i, length, j, bool(rev_flag))
        perm = [perm[s] for s in step]
        cur = cur[np.ix_(step, step)]
    return perm
