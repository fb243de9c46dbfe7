"""Choosing a design: which candidates (each with a Fisher information block) to take so that
the chosen set's information is best, by greedy selection and then single exchanges (Fedorov).

The criterion is ``trace(W M^-1)`` (``W`` given: I-optimal, e.g. the error at the points that
matter) or ``-log det M`` (``W`` None: D-optimal) of ``M = prior + sum of the chosen blocks``.
Each step evaluates every candidate at once through its low-rank factor (the matrix determinant
lemma and Woodbury's identity). Used by the thermal reference plan
(:mod:`robots.thermal.design`) and the calibration tour (:mod:`planner.calibration.select`).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from robots.errors import DesignError


def _criterion(M: NDArray[np.float64], W: NDArray[np.float64] | None) -> NDArray[np.float64]:
    """trace(W M^-1) (W given) or -log det M, of stacked information matrices (lower is better);
    +inf where M is singular."""
    sign, logdet = np.linalg.slogdet(M)
    ok = sign > 0
    if W is None:
        return np.where(ok, -logdet, np.inf)
    out = np.full(M.shape[:-2], np.inf)
    if np.any(ok):
        inv = np.linalg.inv(M[ok])
        out[ok] = np.einsum("ab,kba->k", W, inv)
    return out


def information_factors(blocks: NDArray[np.float64], rel_tol: float = 1e-10) -> NDArray[np.float64]:
    """``U`` (m, p, r) with ``U_j U_j^T = blocks[j]`` (positive semi-definite (m, p, p)); ``r``
    the largest rank among the blocks (eigenvalues below ``rel_tol`` of the largest dropped).
    A view of a board fixes the board's pose in each camera, so ``r`` is small (≤ 12)."""
    w, V = np.linalg.eigh(blocks)
    w = np.clip(w, 0.0, None)
    keep = w > rel_tol * w.max(axis=1, keepdims=True)
    r = max(int(keep.sum(axis=1).max()), 1)
    return V[:, :, -r:] * np.sqrt(w[:, None, -r:])


def _with_each(
    M: NDArray[np.float64], U: NDArray[np.float64], W: NDArray[np.float64] | None
) -> NDArray[np.float64]:
    """The criterion (:func:`_criterion`) of ``M + U_j U_j^T`` for every j, by the matrix
    determinant lemma and Woodbury's identity (``M`` positive definite): r × r work per view."""
    Minv = np.linalg.inv(M)
    MU = Minv @ U  # (m, p, r)
    A = np.eye(U.shape[2]) + np.swapaxes(U, 1, 2) @ MU
    if W is None:
        _, logdet = np.linalg.slogdet(M)
        return -(logdet + np.linalg.slogdet(A)[1])
    C = np.swapaxes(MU, 1, 2) @ (W @ MU)
    return float(np.trace(W @ Minv)) - np.einsum("mrr->m", np.linalg.solve(A, C))


def design_value(
    blocks: NDArray[np.float64],
    rows: list[int],
    prior: NDArray[np.float64],
    W: NDArray[np.float64] | None,
) -> float:
    """``trace(W M^-1)`` (or ``-log det M`` when ``W`` is None) of the views ``rows``."""
    M = prior + blocks[rows].sum(axis=0)
    return float(_criterion(M[None], W)[0])


def choose_by_information(
    blocks: NDArray[np.float64],
    n: int,
    prior: NDArray[np.float64],
    W: NDArray[np.float64] | None = None,
    exchange_passes: int = 10,
    start: list[int] | None = None,
    factors: NDArray[np.float64] | None = None,
    fixed: Sequence[int] = (),
) -> list[int]:
    """Greedy then exchange choice of ``n`` of the views whose information blocks are
    ``blocks`` (m, p, p) (module docstring). ``prior`` (p, p): the information before any view
    (e.g. the parameters' prior σ^-2 on the diagonal, positive definite), which keeps the early
    steps regular.
    ``start``: ``n`` distinct rows to exchange from instead of the greedy choice. ``fixed``:
    rows taken first and never exchanged (without ``start``). Returns rows of ``blocks``
    (greedy: in the order chosen). ``factors``: :func:`information_factors` of ``blocks``, when
    the caller has them (several designs from the same candidates). Raises
    :class:`robots.errors.DesignError` naming what cannot be chosen."""
    m = len(blocks)
    if n < 1 or n > m:
        raise DesignError(f"cannot choose {n} of {m} candidates")
    U = information_factors(blocks) if factors is None else factors
    M = np.asarray(prior, dtype=float).copy()
    if start is not None:
        chosen = [int(k) for k in start]
        if len(set(chosen)) != n or min(chosen) < 0 or max(chosen) >= m:
            raise DesignError(f"a start design must hold {n} distinct rows of {m}")
        M = M + blocks[chosen].sum(axis=0)
    else:
        chosen = [int(k) for k in fixed]
        if chosen:
            M = M + blocks[chosen].sum(axis=0)
    while len(chosen) < n:
        value = _with_each(M, U, W)
        value[chosen] = np.inf
        j = int(np.argmin(value))
        if not np.isfinite(value[j]):
            raise DesignError("every candidate leaves the design undetermined")
        chosen.append(j)
        M = M + blocks[j]
    for _ in range(exchange_passes):
        improved = False
        for slot in range(0 if start is not None else len(fixed), n):
            base = M - blocks[chosen[slot]]
            value = _with_each(base, U, W)
            current = value[chosen[slot]]
            value[[c for k, c in enumerate(chosen) if k != slot]] = np.inf
            j = int(np.argmin(value))
            if value[j] < current - 1e-9 * abs(current) - 1e-12:
                chosen[slot] = j
                M = base + blocks[j]
                improved = True
        if not improved:
            break
    return chosen
