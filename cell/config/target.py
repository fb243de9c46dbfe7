"""The calibration target of a cell file: ``calibration_target:`` (a flat plate board).

::

    calibration_target:
      pattern: chessboard          # or circles (OpenCV's asymmetric circle grid)
      cols: 9                      # inner corners (circles) per row
      rows: 7
      pitch_m: 0.008               # square side (grid pitch), m
      pose: {xyz: [...], rpy: [...]}   # nominal T_cell_target, the board frame in the cell
      plate_thickness_m: 0.005     # the plate's collision box behind the printed face
      flatness_m: 2.0e-5           # optional: the face's flatness tolerance, or ...
      corners_file: board.csv      # ... optional: the measured features, board frame (m)

The board frame is :class:`measure.target.TargetSpec`'s: its origin at the first feature, x
along a row (``cols``), y down the rows, z into the plate (OpenCV's board convention: the
camera looks along +z; the printed face is z = 0 and faces -z). The plate is a collision
obstacle of the cell (a box of the pattern plus its margin, ``plate_thickness_m`` deep); a
stand it sits on is an ``environment.obstacles`` entry like any other.

``corners_file`` is a CSV with the header ``x_m,y_m,z_m``, one row per feature in the
detector's order (:meth:`TargetSpec.object_points`), relative to the cell file. ChArUco boards
are refused: holecell has no ChArUco detection.
"""

from __future__ import annotations

import csv
import math
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, field_validator

from robots import Shape

if TYPE_CHECKING:  # measure.target imports OpenCV: loaded when a board is needed, not with a cell
    from measure.target import TargetSpec

#: a measured feature farther than this fraction of the pitch from the nominal grid is a mistake
CORNER_TOLERANCE_PITCH = 0.25
CORNER_COLUMNS = ("x_m", "y_m", "z_m")
#: a pitch above this is taken for millimetres, not metres
MAX_PITCH_M = 0.2


class CalibrationTargetBoard(BaseModel):
    """The board of a cell's calibration target (its pose is added by :mod:`cell.config`)."""

    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)

    pattern: Literal["chessboard", "circles"]
    cols: Annotated[int, Field(ge=3, le=100)]
    rows: Annotated[int, Field(ge=3, le=100)]
    pitch_m: Annotated[float, Field(gt=0)]
    plate_thickness_m: Annotated[float, Field(gt=0, le=0.05)] = 0.005
    flatness_m: Annotated[float, Field(ge=0, le=1e-3)] | None = None
    corners_file: Annotated[str, Field(min_length=1)] | None = None

    @field_validator("pattern", mode="before")
    @classmethod
    def _known_pattern(cls, v: object) -> object:
        if isinstance(v, str) and v.lower() in ("charuco", "charuco_board", "aruco"):
            raise ValueError("ChArUco boards are not supported (holecell has no ChArUco "
                             "detection): use chessboard or circles")  # fmt: skip
        return v

    @field_validator("pitch_m")
    @classmethod
    def _metres(cls, v: float) -> float:
        if v > MAX_PITCH_M:
            raise ValueError(f"pitch_m is in metres: {v} m looks like millimetres")
        return v

    def model_post_init(self, __context: object) -> None:
        if self.flatness_m is not None and self.corners_file is not None:
            raise ValueError("give flatness_m or corners_file, not both")

    def target_spec(self) -> TargetSpec:
        """The board as :mod:`measure.target` detects and renders it."""
        from measure.target import TargetSpec

        return TargetSpec(self.pattern, self.cols, self.rows, self.pitch_m)

    def corners_path(self, base_dir: Path | None) -> Path | None:
        """``corners_file`` resolved against the cell file's folder (None: none given)."""
        if self.corners_file is None:
            return None
        p = Path(self.corners_file).expanduser()
        return p if p.is_absolute() or base_dir is None else base_dir / p

    def board_points_m(self, base_dir: Path | None) -> np.ndarray:
        """The features in the board frame (N, 3, m): the measured corners if the cell names a
        file, else the nominal grid."""
        path = self.corners_path(base_dir)
        nominal = self.target_spec().object_points()
        if path is None:
            return nominal
        points, problems = read_corners(path, nominal, self.pitch_m)
        if problems:
            raise ValueError(f"{path}: {problems[0]}")
        return points

    def centre_and_normal(self, T_cell_target: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The pattern's centre (cell frame, m) and the printed face's outward unit normal
        (board -z) for the board at ``T_cell_target``."""
        T = np.asarray(T_cell_target, float)
        pts = self.target_spec().object_points()
        c_board = 0.5 * (pts.min(axis=0) + pts.max(axis=0))
        return T[:3, :3] @ c_board + T[:3, 3], -T[:3, 2]

    def plate_shape(self, T_cell_target: np.ndarray) -> Shape:
        """The plate as a collision box (cell frame): the pattern and its margin, behind the
        printed face (board z from 0 to ``plate_thickness_m``)."""
        lo, hi = self.target_spec().plate_bounds()
        centre = np.array([(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, self.plate_thickness_m / 2])
        T = np.eye(4)
        T[:3, 3] = centre
        size = (float(hi[0] - lo[0]), float(hi[1] - lo[1]), self.plate_thickness_m)
        return Shape("box", size, np.asarray(T_cell_target, float) @ T, "calibration_plate")


def read_corners(path: Path, nominal: np.ndarray, pitch_m: float) -> tuple[np.ndarray, list[str]]:
    """Read a measured corner file: ``(points (N, 3) m, problems)``; a problem names the row
    and the column (a missing file, a wrong header, a count other than the board's, a value not
    a finite number, a corner off the nominal grid by more than a quarter pitch)."""
    if not path.is_file():
        return nominal, ["no such file"]
    try:
        with path.open(newline="", encoding="utf-8") as f:
            rows = list(csv.DictReader(f))
            header = tuple(rows[0].keys()) if rows else ()
    except (UnicodeDecodeError, csv.Error) as exc:
        return nominal, [f"not a CSV file: {exc}"]
    if tuple(h.strip() for h in header if h is not None) != CORNER_COLUMNS:
        return nominal, [f"header must be {','.join(CORNER_COLUMNS)} (got {','.join(header)})"]
    if len(rows) != len(nominal):
        return nominal, [f"{len(rows)} corners, the board has {len(nominal)} (cols x rows)"]
    pts = np.zeros((len(rows), 3))
    for i, row in enumerate(rows):
        for k, col in enumerate(CORNER_COLUMNS):
            try:
                v = float(row[col])
            except (TypeError, ValueError):
                v = math.nan
            if not math.isfinite(v):
                return nominal, [f"row {i + 2}, column {col}: {row[col]!r} is not a finite number"]
            pts[i, k] = v
        off = float(np.linalg.norm(pts[i] - nominal[i]))
        if off > CORNER_TOLERANCE_PITCH * pitch_m:
            return nominal, [f"row {i + 2}: {off * 1e3:.2f} mm off the nominal grid (metres? "
                             f"detector order?)"]  # fmt: skip
    return pts, []
