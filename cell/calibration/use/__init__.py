"""The cell calibration used in a run: the calibrated kinematics and point covariance
(:mod:`.apply`), the run's calibration checked and stored (:mod:`.run_calibration`) and the
stops corrected so the calibrated head reaches the planned viewpoints (:mod:`.corrected_tour`)."""

from __future__ import annotations

from cell.calibration.errors import StopCorrectionError
from cell.calibration.use.apply import CalibratedKinematics
from cell.calibration.use.corrected_tour import correct_tour
from cell.calibration.use.run_calibration import (
    MAX_AGE_DAYS,
    RUN_FILENAME,
    RunCalibration,
    RunGeometry,
    calibrated_stereo,
    calibration_summary,
    describe,
    expected_provenance,
    load_run_calibration,
    store_calibration,
    stored_calibration_path,
)

__all__ = [
    "MAX_AGE_DAYS",
    "RUN_FILENAME",
    "CalibratedKinematics",
    "RunCalibration",
    "RunGeometry",
    "StopCorrectionError",
    "calibrated_stereo",
    "calibration_summary",
    "correct_tour",
    "describe",
    "expected_provenance",
    "load_run_calibration",
    "store_calibration",
    "stored_calibration_path",
]
