"""Joint position limits: the URDF's, optionally narrowed by the cell file, never widened."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robots.errors import LimitsError

Array = NDArray[np.float64]

#: a narrowed limit may exceed the URDF's by this much (rad): rounding in the file
WIDEN_TOL_RAD = 1e-9


def narrowed_limits(
    names: Sequence[str], lower: Array, upper: Array, position: ArrayLike | None
) -> tuple[Array, Array]:
    """``(lower, upper)`` (rad): the URDF's limits, or the narrower ``position`` [[lo, hi] x 6].

    Raises :class:`LimitsError` naming the joint for a widening, an empty or a malformed range.
    """
    if position is None:
        return np.array(lower, float), np.array(upper, float)
    given = np.asarray(position, dtype=float)
    if given.shape != (len(names), 2) or not np.all(np.isfinite(given)):
        raise LimitsError("(all joints)", f"needs {len(names)} pairs [lower, upper] in rad")
    for i, name in enumerate(names):
        lo, hi = given[i]
        if lo >= hi:
            raise LimitsError(name, f"lower {lo:.6g} rad is not below upper {hi:.6g} rad")
        if lo < lower[i] - WIDEN_TOL_RAD or hi > upper[i] + WIDEN_TOL_RAD:
            raise LimitsError(
                name,
                f"[{lo:.6g}, {hi:.6g}] rad widens the URDF's limits "
                f"[{lower[i]:.6g}, {upper[i]:.6g}] rad (limits may only be narrowed)",
            )
    return np.maximum(given[:, 0], lower), np.minimum(given[:, 1], upper)
