"""Errors of :mod:`cell.referencing`, derived from :class:`cell.errors.CellError`."""

from __future__ import annotations

from cell.errors import CellError


class ReferencingError(CellError):
    """Base of the referencing errors."""


class SurveyRefusedError(ReferencingError):
    """The survey's views cannot determine the marker network; ``what`` names the marker,
    view or pair of pieces, ``reason`` says why. Nothing is written."""

    def __init__(self, what: str, reason: str) -> None:
        self.what, self.reason = what, reason
        super().__init__(f"survey refused: {what}: {reason}; nothing written")


class MarkersFileError(ReferencingError):
    """``markers.json`` is unreadable, malformed or belongs to another cell or head."""

    def __init__(self, path: str, field: str, reason: str) -> None:
        self.path, self.field, self.reason = path, field, reason
        super().__init__(f"{path}: {field}: {reason}")
