"""Errors of :mod:`cell.run`, derived from :class:`cell.errors.CellError`."""

from __future__ import annotations

from cell.errors import CellError


class ThermalModelMismatchError(CellError):
    """A thermal model file was made for another cell, arm, tool or sensor set."""

    def __init__(self, where: str, field: str, model_value: object, cell_value: object) -> None:
        self.where, self.field = where, field
        super().__init__(
            f"{where}: {field} is {model_value} in the thermal model but {cell_value} in the "
            "cell: identify a model for this cell (holecell thermal identify) or run without "
            "--thermal"
        )
