"""Errors of :mod:`cell.uncertainty`, derived from :class:`cell.errors.CellError`."""

from __future__ import annotations

from cell.errors import CellError


class PartTemperatureError(CellError):
    """A part temperature reading that cannot be right (names where it came from)."""

    def __init__(self, source: str, value: object, reason: str) -> None:
        self.source, self.value, self.reason = source, value, reason
        super().__init__(f"{source}: {reason} (value: {value!r})")
