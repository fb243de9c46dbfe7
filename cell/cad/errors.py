"""Errors of :mod:`cell.cad`, derived from :class:`cell.errors.CellError`."""

from __future__ import annotations

from pathlib import Path

from cell.errors import CellError


class CadError(CellError):
    """A CAD file cannot be used: ``path`` the file, ``where`` the entity or field (``entity
    #20 CARTESIAN_POINT``, ``line 33``, ``--deflection``), ``reason`` what is wrong. One line."""

    def __init__(self, path: str | Path, where: str, reason: str) -> None:
        self.path, self.where, self.reason = str(path), where, reason
        super().__init__(f"{path}: {where}: {reason}")
