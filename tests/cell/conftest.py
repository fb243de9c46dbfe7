"""Fixtures of the cell tests (defined in :mod:`cell_fixtures`)."""

from cell_fixtures import controller, controller_rapid_slow, private_cache, small_cell

__all__ = ["controller", "controller_rapid_slow", "private_cache", "small_cell"]
