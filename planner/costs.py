"""Travel-time costs between joint configurations, vectorised in numpy.

The cost of moving between two configurations is the duration of ruckig's
time-synchronised rest-to-rest trajectory: the largest of the per-joint
time-optimal rest-to-rest durations under velocity, acceleration and jerk
limits. For one joint that duration has a closed form (a symmetric profile of
jerk, constant acceleration, jerk, then cruise), so whole cost matrices are
computed in numpy without calling ruckig; ``tests/planner`` checks the formula
against ruckig itself.
"""

from __future__ import annotations

from functools import lru_cache
from typing import TypeVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

_F = TypeVar("_F", np.float32, np.float64)


def rest_to_rest_time(
    distance_rad: ArrayLike,
    v_max: ArrayLike,
    a_max: ArrayLike,
    j_max: ArrayLike,
) -> NDArray[np.float64]:
    """Time-optimal rest-to-rest duration (s) of one joint moving ``|distance_rad|``.

    All arguments broadcast; limits are positive (rad/s, rad/s^2, rad/s^3). Three
    regimes by distance: jerk only (peak acceleration below ``a_max``), jerk and
    constant acceleration (peak velocity below ``v_max``), and a cruise at ``v_max``.
    """
    d = np.abs(np.asarray(distance_rad, dtype=float))
    v = np.asarray(v_max, dtype=float)
    a = np.asarray(a_max, dtype=float)
    j = np.asarray(j_max, dtype=float)
    reaches_a = v * j >= a * a
    t_acc = np.where(reaches_a, v / a + a / j, 2.0 * np.sqrt(v / j))
    d_cruise = v * t_acc  # shortest distance that reaches v_max (both ramps)
    d_jerk = 2.0 * a**3 / j**2  # longest distance whose peak acceleration stays below a_max
    t_cruise = 2.0 * t_acc + (d - d_cruise) / v
    t_jerk = 4.0 * np.cbrt(0.5 * d / j)
    t_trap = np.sqrt((a / j) ** 2 + 4.0 * d / a) + a / j
    return np.where(d >= d_cruise, t_cruise, np.where(d <= d_jerk, t_jerk, t_trap))


def travel_time(
    q_from: ArrayLike,
    q_to: ArrayLike,
    v_max: ArrayLike,
    a_max: ArrayLike,
    j_max: ArrayLike,
) -> NDArray[np.float64]:
    """Rest-to-rest synchronised duration (s) between configurations, broadcast over rows.

    ``q_from`` and ``q_to`` have shape (..., n_joints) in rad; the result has shape (...).
    """
    delta = np.asarray(q_to, dtype=float) - np.asarray(q_from, dtype=float)
    return rest_to_rest_time(delta, v_max, a_max, j_max).max(axis=-1)


def cost_matrix(
    q_rows: ArrayLike,
    q_cols: ArrayLike,
    v_max: ArrayLike,
    a_max: ArrayLike,
    j_max: ArrayLike,
) -> NDArray[np.float64]:
    """Matrix of rest-to-rest durations (s): entry (i, k) moves from ``q_rows[i]`` to ``q_cols[k]``.

    Computed joint by joint (2-D temporaries only): the entry is the largest
    per-joint duration.
    """
    rows = np.atleast_2d(np.asarray(q_rows, dtype=float))
    cols = np.atleast_2d(np.asarray(q_cols, dtype=float))
    v, a, j = (
        np.broadcast_to(np.asarray(x, float), (rows.shape[1],)) for x in (v_max, a_max, j_max)
    )
    out = np.zeros((rows.shape[0], cols.shape[0]))
    for k in range(rows.shape[1]):
        delta = np.subtract.outer(rows[:, k], cols[:, k])
        np.maximum(out, rest_to_rest_time(delta, v[k], a[k], j[k]), out=out)
    return out


#: rows per block of a symmetric :meth:`CostTable.matrix`
SYMMETRIC_BLOCK = 256


class CostTable:
    """Fast approximate travel-time matrices from per-joint lookup tables.

    Each joint's rest-to-rest duration is tabulated every ``step_rad`` up to
    ``span_rad``; a matrix entry is the largest table value over joints for the
    distances rounded down to the grid (error below the duration of a
    ``step_rad`` move, ~1e-4 s for moves over 0.01 rad). Used where many entries
    are needed (sequencing); :func:`cost_matrix` gives exact values.
    """

    def __init__(
        self,
        v_max: ArrayLike,
        a_max: ArrayLike,
        j_max: ArrayLike,
        span_rad: ArrayLike,
        step_rad: float = 2e-5,
    ) -> None:
        v, a, j, span = np.broadcast_arrays(
            *(np.asarray(x, dtype=float) for x in (v_max, a_max, j_max, span_rad))
        )
        self.inv_step = 1.0 / step_rad
        self.tables = []
        for k in range(v.shape[0]):
            grid = np.arange(int(np.ceil(span[k] * self.inv_step)) + 2) * step_rad
            self.tables.append(rest_to_rest_time(grid, v[k], a[k], j[k]).astype(np.float32))

    def matrix(self, q_rows: ArrayLike, q_cols: ArrayLike) -> NDArray[np.float32]:
        """Approximate :func:`cost_matrix` (s, float32) between the rows of two arrays (rad).

        When ``q_cols`` is ``q_rows`` (the same object) the matrix is symmetric (the table's
        argument is ``|a - b|``, exactly the same both ways in floating point): the upper
        triangle is computed in blocks of rows and mirrored, about half the work.
        """
        rows = np.atleast_2d(np.asarray(q_rows, dtype=float))
        if q_cols is not q_rows:
            return self._block(rows, np.atleast_2d(np.asarray(q_cols, dtype=float)))
        n = rows.shape[0]
        return self._symmetric(rows, np.zeros((n, n), dtype=np.float32))

    def matrix64(self, q: ArrayLike) -> NDArray[np.float64]:
        """``matrix(q, q)`` as float64 (the same values), made in place: no float32 copy of
        the whole matrix (250 holes: 58 MB less, and one pass over it fewer)."""
        rows = np.atleast_2d(np.asarray(q, dtype=float))
        n = rows.shape[0]
        return self._symmetric(rows, np.zeros((n, n), dtype=np.float64))

    def _symmetric(self, rows: NDArray[np.float64], out: NDArray[_F]) -> NDArray[_F]:
        return self.symmetric_rows(rows, out, 0, rows.shape[0])

    def symmetric_rows(
        self, rows: NDArray[np.float64], out: NDArray[_F], r0: int, r1: int
    ) -> NDArray[_F]:
        """Fill the entries of ``out`` (the symmetric matrix of ``rows``) whose smaller index
        is in ``[r0, r1)`` (``r0`` a multiple of ``SYMMETRIC_BLOCK``): two calls on split
        ranges, in two processes, fill the matrix of one call with the same values."""
        n = rows.shape[0]
        for i0 in range(r0, min(r1, n), SYMMETRIC_BLOCK):
            i1 = min(i0 + SYMMETRIC_BLOCK, n)
            block = self._block(rows[i0:i1], rows[i0:])
            out[i0:i1, i0:] = block
            out[i0:, i0:i1] = block.T
        return out

    def _block(self, rows: NDArray[np.float64], cols: NDArray[np.float64]) -> NDArray[np.float32]:
        out = np.zeros((rows.shape[0], cols.shape[0]), dtype=np.float32)
        delta = np.empty_like(out)
        idx = np.empty(out.shape, dtype=np.int32)
        for k, table in enumerate(self.tables):
            a = (rows[:, k] * self.inv_step).astype(np.float32)
            b = (cols[:, k] * self.inv_step).astype(np.float32)
            np.subtract(a[:, None], b[None, :], out=delta)
            np.abs(delta, out=delta)
            np.minimum(delta, np.float32(len(table) - 1), out=delta)
            idx[...] = delta
            np.maximum(out, table[idx], out=out)
        return out


def cost_table(
    v_max: ArrayLike, a_max: ArrayLike, j_max: ArrayLike, span_rad: ArrayLike
) -> CostTable:
    """The :class:`CostTable` of these limits (rad/s, rad/s², rad/s³, rad), made once per
    process: an arm's table is the same for every plan (250 holes: ~0.07 s and 9 MB)."""
    key = tuple(tuple(np.broadcast_to(np.asarray(x, float), np.shape(v_max)).tolist())
                for x in (v_max, a_max, j_max, span_rad))  # fmt: skip
    return _table_of(key)


@lru_cache(maxsize=4)
def _table_of(key: tuple[tuple[float, ...], ...]) -> CostTable:
    v, a, j, span = (np.array(x) for x in key)
    return CostTable(v, a, j, span)
