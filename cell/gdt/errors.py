"""The exception of :mod:`cell.gdt`."""

from __future__ import annotations

from cell.errors import CellError


class GdtError(CellError):
    """A datum reference frame or a characteristic cannot be evaluated: ``what`` names it."""

    def __init__(self, what: str, reason: str) -> None:
        self.what = what
        self.reason = reason
        super().__init__(f"{what}: {reason}")
