"""The calibration target as the view planner needs it: the features' positions and the pose.

:func:`cell_target` reads the cell file's ``calibration_target``; :func:`board_of` turns a
:class:`TargetGeometry` into the planner's :class:`planner.calibration.Board` (features in
detector order, from :class:`measure.target.TargetSpec`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from cell.config import CellConfig
from cell.errors import CellError
from measure.target import TargetSpec
from planner.calibration import Board
from planner.calibration.tour import pose_dict


@dataclass(frozen=True)
class TargetGeometry:
    """A plate target: ``pattern`` (``chessboard`` or ``circles``), ``cols`` × ``rows``
    features, ``pitch_m``, ``T_cell_target`` (4×4, m) its nominal pose in the cell (board frame:
    :mod:`cell.config.target`), ``points_m`` (n, 3, m) the measured features in the board frame
    (``None``: the nominal grid)."""

    pattern: str
    cols: int
    rows: int
    pitch_m: float
    T_cell_target: NDArray[np.float64]
    points_m: NDArray[np.float64] | None = None

    def spec(self) -> TargetSpec:
        """The target as :mod:`measure.target` detects it."""
        try:
            return TargetSpec(self.pattern, self.cols, self.rows, self.pitch_m)
        except ValueError as exc:
            raise CellError(f"calibration_target: {exc}") from exc

    def to_dict(self) -> dict[str, Any]:
        """The target as written to ``caltour.json`` (``calibration.target``)."""
        return {
            "pattern": self.pattern,
            "cols": self.cols,
            "rows": self.rows,
            "pitch_m": self.pitch_m,
            "pose": pose_dict(self.T_cell_target),
        }


def board_of(target: TargetGeometry) -> Board:
    """The planner's board of ``target``."""
    points = target.spec().object_points() if target.points_m is None else target.points_m
    return Board(np.asarray(target.T_cell_target, dtype=float), points, "calibration_target")


def cell_target(cell: CellConfig) -> TargetGeometry:
    """The cell file's ``calibration_target`` (its measured corners when it names a file); a
    :class:`CellError` when it has none."""
    t = cell.calibration_target
    if t is None:
        raise CellError(
            f"cell {cell.name!r}: calibration_target: missing; the cell file must place the "
            "calibration target (pattern, cols, rows, pitch_m, pose) to plan its views"
        )
    try:
        points = t.board_points_m(cell.base_dir) if t.corners_file is not None else None
    except ValueError as exc:
        raise CellError(f"calibration_target.corners_file: {exc}") from exc
    return TargetGeometry(t.pattern, t.cols, t.rows, t.pitch_m, t.T_cell_target(), points)
