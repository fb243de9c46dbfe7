"""The cell calibration's estimate: observations (:mod:`.observations`) -> refusals
(:mod:`.refusals`) -> OpenCV start (:mod:`.initial`) -> identifiability (:mod:`.identifiability`)
-> adjustment (:mod:`.solve`, model :mod:`.model`, covariance :mod:`.covariance`) -> the result
(:mod:`.result`); :mod:`.synthetic` simulates views with a known truth."""

from __future__ import annotations

from cell.calibration.estimate.covariance import ViewWhitening, white_covariance
from cell.calibration.estimate.initial import hand_eye_candidates, initial_estimate, solve_pnp
from cell.calibration.estimate.model import (
    State,
    column_names,
    corrected,
    flange_poses,
    perturb_pose,
    predict,
    step_state,
)
from cell.calibration.estimate.observations import CalibrationObservations, CalibrationView, Cameras
from cell.calibration.estimate.result import CellCalibration, PoseEstimate, Provenance
from cell.calibration.estimate.solve import (
    CalibrationResult,
    SolveOptions,
    pose_error,
    solve_calibration,
)
from cell.calibration.estimate.synthetic import (
    SyntheticTruth,
    example_truth,
    parameter_errors,
    random_truth,
    reference_joints,
    seen_view_joints,
    simulate,
    truth_in_gauge,
    view_joints,
)

__all__ = [
    "CalibrationObservations",
    "CalibrationResult",
    "CalibrationView",
    "Cameras",
    "CellCalibration",
    "PoseEstimate",
    "Provenance",
    "SolveOptions",
    "State",
    "SyntheticTruth",
    "ViewWhitening",
    "column_names",
    "corrected",
    "example_truth",
    "flange_poses",
    "hand_eye_candidates",
    "initial_estimate",
    "parameter_errors",
    "perturb_pose",
    "pose_error",
    "predict",
    "random_truth",
    "reference_joints",
    "seen_view_joints",
    "simulate",
    "solve_calibration",
    "solve_pnp",
    "step_state",
    "truth_in_gauge",
    "view_joints",
    "white_covariance",
]
