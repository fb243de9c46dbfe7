"""Fixtures of the cell tests (defined in :mod:`cell_fixtures`)."""

from cell_fixtures import small_cell

__all__ = ["small_cell"]
