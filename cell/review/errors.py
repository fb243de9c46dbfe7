"""Errors of :mod:`cell.review`, derived from :class:`cell.errors.CellError`."""

from __future__ import annotations

from pathlib import Path

from cell.errors import CellError


class StoreError(CellError):
    """The store cannot be created or used (exists already, corrupt, foreign, duplicate hole)."""

    def __init__(self, path: str | Path, reason: str) -> None:
        self.path = str(path)
        self.reason = reason
        super().__init__(f"{path}: {reason}")
