"""A small cell for the referencing tests: the built-in cell cut to a few holes near the pivot,
their markers, the table's markers and the two scale bars (the survey of the whole frame is
the benchmark's)."""

from __future__ import annotations

import pytest
from referencing_cells import small_cell_text

from cell.camera import cell_stereo
from cell.config import builtin_cell_path, parse_cell
from cell.referencing.synthetic import draw_marker_truth


@pytest.fixture(scope="session")
def small_cell():
    return parse_cell(small_cell_text(), "small.yaml", builtin_cell_path())


@pytest.fixture(scope="session")
def stereo(small_cell):
    return cell_stereo(small_cell)


@pytest.fixture(scope="session")
def marker_truth(small_cell):
    return draw_marker_truth(small_cell, seed=3)
