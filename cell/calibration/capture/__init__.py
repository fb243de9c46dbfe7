"""The cell calibration run in the cell (``holecell calibrate cell``): the calibration tour on
the controller and the stereo head (:mod:`.capture`), then one adjustment of every view
(:mod:`.run`). See docs/calibration.md."""

from __future__ import annotations

from cell.calibration.capture.capture import (
    CapturedView,
    CaptureSettings,
    TourCapture,
    TourCaptures,
)
from cell.calibration.capture.orient import (
    PLANE_TOLERANCE_PX,
    orient_chessboard,
    plane_outliers,
    refine_corners,
    repair_outliers,
)
from cell.calibration.capture.tour import (
    CalibrateCellOptions,
    CapturedTour,
    CellCalibrationRun,
    calibrate_cell,
    capture_calibration_tour,
    check_calibration_tour,
    finish_calibration_tour,
    observations_of,
    run_calibration_tour,
    solve_captured,
)

__all__ = [
    "PLANE_TOLERANCE_PX",
    "CalibrateCellOptions",
    "CaptureSettings",
    "CapturedTour",
    "CapturedView",
    "CellCalibrationRun",
    "TourCapture",
    "TourCaptures",
    "calibrate_cell",
    "capture_calibration_tour",
    "check_calibration_tour",
    "finish_calibration_tour",
    "observations_of",
    "orient_chessboard",
    "plane_outliers",
    "refine_corners",
    "repair_outliers",
    "run_calibration_tour",
    "solve_captured",
]
