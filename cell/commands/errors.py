"""Errors of :mod:`cell.commands`, derived from :class:`cell.errors.CellError`."""

from __future__ import annotations

from cell.errors import CellError


class CalibrateUsageError(CellError):
    """``holecell calibrate`` without a subcommand and without the old form's options."""
