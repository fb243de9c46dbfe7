"""The plain inputs of the calibration-view planner: the board and the stereo head.

The planner never reads a cell file or a calibration file: the cell side builds these from its
config (:mod:`cell.calibration.plan`) and hands them over as arrays and callables.

Board frame (``target``): OpenCV's board convention (``docs/conventions.md``): the features lie
in its x-y plane (z = 0), in detector order, z points into the plate and the printed face faces
-z, so a camera sees the board looking along +z.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from planner.errors import PlanningError

#: projects points (n, 3) in one camera's optical frame (m) to pixels (n, 2), distortion included
Projector = Callable[[NDArray[np.float64]], NDArray[np.float64]]


@dataclass(frozen=True)
class Board:
    """A calibration plate at its nominal pose.

    ``T_cell_target`` (4×4, m): the board frame in the cell. ``points_target`` (n, 3, m): the
    features (corners or circle centres) in the board frame, z = 0. ``name`` is for messages.
    """

    T_cell_target: NDArray[np.float64]
    points_target: NDArray[np.float64]
    name: str = "calibration_target"

    def __post_init__(self) -> None:
        T = np.asarray(self.T_cell_target, dtype=float)
        P = np.asarray(self.points_target, dtype=float)
        if T.shape != (4, 4) or not np.all(np.isfinite(T)):
            raise PlanningError(f"{self.name}: pose must be a finite 4x4 transform")
        if P.ndim != 2 or P.shape[1] != 3 or len(P) < 4 or not np.all(np.isfinite(P)):
            raise PlanningError(f"{self.name}: needs at least 4 finite feature points (n, 3)")
        if np.ptp(P[:, 2]) > 1e-9:
            raise PlanningError(f"{self.name}: feature points must lie in the plane z = 0")

    @property
    def centre_target(self) -> NDArray[np.float64]:
        """The features' centroid in the board frame (m)."""
        return np.asarray(self.points_target, dtype=float).mean(axis=0)

    @property
    def points_cell(self) -> NDArray[np.float64]:
        """The features in the cell frame (n, 3, m)."""
        T = np.asarray(self.T_cell_target, dtype=float)
        return np.asarray(self.points_target, dtype=float) @ T[:3, :3].T + T[:3, 3]

    @property
    def normal_cell(self) -> NDArray[np.float64]:
        """The printed face's outward normal (the board's -z) in the cell frame."""
        return -np.asarray(self.T_cell_target, dtype=float)[:3, 2]

    @property
    def size_m(self) -> float:
        """The features' largest extent (m)."""
        P = np.asarray(self.points_target, dtype=float)
        return float(np.linalg.norm(np.ptp(P[:, :2], axis=0)))


@dataclass(frozen=True)
class StereoModel:
    """The stereo head as the planner needs it.

    ``T_tcp_left`` / ``T_tcp_right`` (4×4, m): the camera optical frames in the TCP frame
    (x right, y down, z forward). ``image_size`` ``(width, height)`` px. ``project_left`` /
    ``project_right``: each camera's projection (:data:`Projector`), the cell's lens model.
    """

    T_tcp_left: NDArray[np.float64]
    T_tcp_right: NDArray[np.float64]
    image_size: tuple[int, int]
    project_left: Projector
    project_right: Projector
