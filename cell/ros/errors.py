"""Errors of :mod:`cell.ros`, derived from :class:`cell.errors.CellError`."""

from __future__ import annotations

from pathlib import Path

from cell.errors import CellError


class BagError(CellError):
    """A bag cannot be written (``path``) for ``reason``."""

    def __init__(self, path: str | Path, reason: str) -> None:
        self.path, self.reason = str(path), reason
        super().__init__(f"{path}: {reason}")
