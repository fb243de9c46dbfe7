"""Views dropped for a quality check, and the solve that goes on without them.

A view whose image fails a quality check (today: the sharpness of ``measure.target.find_target``,
"too blurred (edge width w px)") is not evidence against the rest: by default it is dropped,
named in a warning, and the calibration goes on with the remaining views when they still pass
every identifiability check of :func:`cell.calibration.estimate.solve.solve_calibration`
(enough views, rotations about axes far from parallel, the rank test). When they do not, the
refusal names the dropped views and why the rest cannot be calibrated. ``strict`` keeps the
old refusal of the whole set at the first soft view. A view without the target at all, an
unreadable image or a wrong board is still refused: those are mistakes, not soft images.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from cell.calibration.errors import CalibrationDataError, DegenerateCalibrationError

#: the reasons of :func:`measure.target.find_target` that are a quality check
SOFT_REASONS = ("too blurred",)


@dataclass(frozen=True)
class DroppedView:
    """A view left out: its row (CSV data row or view id) and the quality check it failed."""

    row: int | str
    reason: str

    def warning(self, source: str, left: int) -> str:
        """The one-line warning (``left``: the views kept)."""
        return (f"warning: {source}, row {self.row}: {self.reason}: view dropped, {left} "
                "views left (--strict refuses instead; --max-edge-width accepts softer "
                "images)")  # fmt: skip


def is_soft(reason: str) -> bool:
    """Whether a detection's ``reason`` is a failed quality check (module docstring)."""
    return reason.startswith(SOFT_REASONS)


def solve_without(dropped: list[DroppedView], source: str, solve: Any, *args: Any) -> Any:
    """``solve(*args)``; when views were dropped and the rest is not identifiable, a refusal
    naming them (:class:`CalibrationDataError`) instead of the bare degenerate-set error."""
    try:
        return solve(*args)
    except DegenerateCalibrationError as exc:
        if not dropped:
            raise
        names = "; ".join(f"row {d.row}: {d.reason}" for d in dropped)
        raise CalibrationDataError(
            source, f"without the views dropped for their quality ({names}) the rest cannot be "
            f"calibrated: {exc.reason}; nothing written"
        ) from None  # fmt: skip
