"""Which unknowns of the cell calibration the views determine: rank of the Jacobian.

As :mod:`robots.thermal.identify` does: first the D-H terms that other unknowns absorb by the
table's shape (:func:`robots.calibration.structural_redundancies`) are fixed at zero; then terms
whose effect on the corners is below ``effect_floor_px``; then, while the condition number of
the column-normalised Jacobian exceeds ``max_condition``, the D-H term with the largest share
of the least determined direction is fixed, with the terms it is confused with named. Poses
are never fixed: when the least determined direction lies in them, the data set is refused.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from cell.calibration.errors import DegenerateCalibrationError

Array = NDArray[np.float64]


@dataclass(frozen=True)
class IdentifiabilityReport:
    """Rank and condition of the adjustment.

    Attributes:
        candidates: every unknown considered (Jacobian columns).
        free: the unknowns estimated.
        fixed: unknown -> reason, for every unknown held at its starting value (D-H terms: 0).
        singular_values: of the column-normalised Jacobian of the candidates that have an
            effect and are not structurally redundant (descending).
        rank: how many of those exceed ``s_max / max_condition``.
        condition_all: their condition number (inf when singular).
        condition_free: condition number of the free unknowns.
    """

    candidates: tuple[str, ...]
    free: tuple[str, ...]
    fixed: dict[str, str]
    singular_values: tuple[float, ...]
    rank: int
    condition_all: float
    condition_free: float


def _normalised_svd(J: Array) -> tuple[Array, Array]:
    """Singular values (descending) and right singular vectors (rows) of ``J`` with unit
    columns, from the eigen-decomposition of the small normal matrix (no SVD of the tall ``J``:
    multi-threaded LAPACK on a loaded machine spends 30x longer on it)."""
    norms = np.linalg.norm(J, axis=0)
    Jn = J / np.where(norms > 0, norms, 1.0)
    w, V = np.linalg.eigh(Jn.T @ Jn)
    order = np.argsort(w)[::-1]
    return np.sqrt(np.clip(w[order], 0.0, None)), V[:, order].T


def _condition(s: Array) -> float:
    return float(s[0] / s[-1]) if s[-1] > 0 else float("inf")


def choose_free(
    J: Array,
    columns: tuple[str, ...],
    structural: dict[str, str],
    max_condition: float,
    effect_floor_px: float,
) -> IdentifiabilityReport:
    """Split the columns of ``J`` (residual rows x unknowns, px per m or rad) into free and fixed.

    ``structural`` maps D-H column names (``"dh.d1_m"``) to the reason they are redundant.
    Raises :class:`DegenerateCalibrationError` when a pose is not determined.
    """
    fixed = dict(structural)
    norms = np.linalg.norm(J, axis=0)
    for k, name in enumerate(columns):
        if name in fixed:
            continue
        if norms[k] < effect_floor_px:
            if not name.startswith("dh."):
                raise DegenerateCalibrationError(f"{name} has no effect on the corners seen")
            fixed[name] = f"no effect on these views (moves the corners {norms[k]:.2g} px per unit)"
    free = [c for c in columns if c not in fixed]
    s_all, _ = _normalised_svd(J[:, [columns.index(c) for c in free]])
    while True:
        idx = [columns.index(c) for c in free]
        s, vt = _normalised_svd(J[:, idx])
        cond = _condition(s)
        if cond <= max_condition:
            break
        v = vt[-1]
        dh = [i for i, c in enumerate(free) if c.startswith("dh.")]
        share = np.abs(v)
        if not dh or share[dh].max() < 0.2:
            worst = free[int(np.argmax(share))]
            raise DegenerateCalibrationError(
                f"the views cannot determine {worst.split('.')[0]} (condition number {cond:.3g} "
                f"of the adjustment; its least determined direction is mostly {worst}): add views "
                "with larger rotations about different axes"
            )
        k = dh[int(np.argmax(share[dh]))]
        partners = [free[i] for i in np.argsort(-share) if i != k and share[i] > 0.2][:3]
        fixed[free[k]] = (
            f"not determined by these views (condition number {cond:.3g} > {max_condition:g}"
            + (f"; confused with {', '.join(partners)}" if partners else "")
            + ")"
        )
        del free[k]
    return IdentifiabilityReport(
        candidates=tuple(columns),
        free=tuple(free),
        fixed={c: fixed[c] for c in columns if c in fixed},
        singular_values=tuple(float(x) for x in s_all),
        rank=int(np.sum(s_all > s_all[0] / max_condition)),
        condition_all=_condition(s_all),
        condition_free=cond,
    )
