"""How much the arm warmed during the calibration tour, and the limit past which it is refused.

The adjustment takes the arm as one rigid kinematic chain over the whole tour. An arm that
warms while the tour runs (a cold start) grows by the steel's expansion, and the adjustment
puts that growth into the D-H lengths (a2, d4): on the simulator a cold 120-view tour read a2
0.178 mm off, about 40 sigma (issue 26). So every view's temperature readings are kept with
it, and the tour's warming is measured and reported: the largest change of any sensor between
the views (K). Past :data:`WARN_K` a warning; past the limit (:data:`MAX_K` by default,
``--max-warming-k``) the calibration is refused: warm the arm up first (run it, or wait for
steady readings) or plan a shorter tour. docs/calibration.md gives the figures.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from cell.calibration.errors import CalibrationDataError

#: a warming over this (K) is reported as a warning
WARN_K = 0.3
#: a warming over this (K) refuses the calibration by default
MAX_K = 1.0


@dataclass(frozen=True)
class TourWarming:
    """The largest change of one sensor over the tour's views (K), which sensor (1-based),
    its first and last reading (°C) and the tour's length on the controller clock (s)."""

    change_K: float  # noqa: N815 (unit suffix)
    sensor: int
    first_c: float
    last_c: float
    duration_s: float

    def line(self) -> str:
        """One line for the terminal and the calibration's notes."""
        return (f"arm warming during the tour: {self.change_K:.2f} K (sensor {self.sensor}: "
                f"{self.first_c:.2f} -> {self.last_c:.2f} °C over "
                f"{self.duration_s:.0f} s)")  # fmt: skip


def tour_warming(temps_c: list[np.ndarray | None], times_s: list[float]) -> TourWarming | None:
    """The warming of a tour from each view's readings (°C; None: not read), or None when
    fewer than two views were read."""
    rows = [(t, np.asarray(T, float)) for t, T in zip(times_s, temps_c, strict=True)
            if T is not None and len(T)]  # fmt: skip
    if len(rows) < 2:
        return None
    T = np.array([r for _, r in rows])
    spread = T.max(axis=0) - T.min(axis=0)
    j = int(np.argmax(spread))
    return TourWarming(float(spread[j]), j + 1, float(T[0, j]), float(T[-1, j]),
                       float(rows[-1][0] - rows[0][0]))  # fmt: skip


def check_warming(w: TourWarming | None, max_K: float, source: str) -> str:
    """The warning for a warming past :data:`WARN_K` ("" below it); refuses one past
    ``max_K`` (:class:`CalibrationDataError`, one line)."""
    if w is None:
        return ""
    if w.change_K > max_K:
        raise CalibrationDataError(
            source, f"{w.line()}, over the {max_K:g} K limit: the arm's growth would be read as "
            "D-H errors; warm the arm up (or wait for steady readings) and run the tour again, "
            "or raise --max-warming-k; nothing written")  # fmt: skip
    if w.change_K <= WARN_K:
        return ""
    return f"warning: {w.line()}, over {WARN_K:g} K: the D-H lengths absorb part of the growth"
