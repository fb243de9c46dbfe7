"""Exceptions of :mod:`cell.calibration`, all subclasses of :class:`cell.errors.CellError`."""

from __future__ import annotations

from cell.errors import CellError


class CalibrationDataError(CellError):
    """Observations, poses or images cannot be used; ``source`` names the file or data set,
    ``row`` the view (a CSV data row, 1-based, or an image name) when one is to blame."""

    def __init__(self, source: str, reason: str, row: int | str | None = None) -> None:
        self.source = source
        self.reason = reason
        self.row = row
        where = source if row is None else f"{source}, row {row}"
        super().__init__(f"{where}: {reason}")


class DegenerateCalibrationError(CellError):
    """The views cannot determine the hand-eye (too few, parallel rotation axes, target unseen)."""

    def __init__(self, reason: str) -> None:
        self.reason = reason
        super().__init__(f"calibration refused: {reason}")


class CalibrationFileError(CellError):
    """A ``cellcal.json`` file is missing a field, holds a bad value or belongs elsewhere."""

    def __init__(self, path: str, field: str, reason: str) -> None:
        self.path = path
        self.field = field
        self.reason = reason
        super().__init__(f"{path}: {field}: {reason}")


class TargetNotFoundError(CalibrationDataError):
    """One image does not show the (whole, sharp) target; the image itself could be read."""


class StopCorrectionError(CellError):
    """A stop cannot be corrected for the calibration (limits, no convergence)."""

    def __init__(self, where: str, stop: int, hole_id: str, reason: str) -> None:
        self.stop, self.hole_id, self.reason = stop, hole_id, reason
        super().__init__(f"{where}: stop {stop} ({hole_id}): {reason}")
