"""The identity of a cell for a tour: a tour is only run on the cell it was planned for."""

from __future__ import annotations

import hashlib

from planner.errors import TourCellMismatchError
from planner.protocols import CellLike
from planner.tour import Tour


def cell_sha256(cell: CellLike) -> str:
    """Identity of a cell: SHA-256 of its file text (or of its name and holes if built in code)."""
    text = cell.raw_text
    if not text:
        holes = [
            (h.id, h.position_m.round(9).tolist(), h.normal.round(9).tolist())
            for h in cell.holes_in_cell()
        ]
        text = repr((cell.name, cell.robot.model, cell.home_q().round(9).tolist(), holes))
    return hashlib.sha256(text.encode()).hexdigest()


def check_tour_for_cell(tour: Tour, cell: CellLike) -> None:
    """Raise :class:`TourCellMismatchError` unless ``tour`` was planned for exactly ``cell``.

    Compares the robot model, the cell name and the SHA-256 of the cell file text.
    """
    checks = (
        ("robot model", tour.robot_model, cell.robot.model),
        ("cell name", tour.cell_name, cell.name),
        ("cell sha256", tour.cell_sha256, cell_sha256(cell)),
    )
    for field, in_tour, in_cell in checks:
        if in_tour != in_cell:
            raise TourCellMismatchError(field, in_tour, in_cell)
