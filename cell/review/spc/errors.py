"""Errors of :mod:`cell.review.spc`, derived from :class:`cell.errors.CellError`."""

from __future__ import annotations

from cell.errors import CellError


class SpcError(CellError):
    """The runs of an SPC study cannot be used; the message names the path or characteristic."""
