"""The cell calibration run in the cell (``holecell calibrate cell``): the calibration tour on
the controller and the stereo head (:mod:`.capture`), then one adjustment of every view
(:mod:`.run`). See docs/calibration.md."""

from cell.calibration_run.capture import CapturedView, CaptureSettings, TourCaptures
from cell.calibration_run.run import (
    CalibrateCellOptions,
    CellCalibrationRun,
    calibrate_cell,
    run_calibration_tour,
)

__all__ = [
    "CalibrateCellOptions",
    "CaptureSettings",
    "CapturedView",
    "CellCalibrationRun",
    "TourCaptures",
    "calibrate_cell",
    "run_calibration_tour",
]
