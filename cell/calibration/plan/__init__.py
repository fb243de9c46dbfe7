"""The calibration tour of a cell (``holecell plan-calibration``): the cell's target and head as
the view planner takes them (:mod:`.target`, :mod:`.head_model`), the information-based design
on the cell calibration's own Jacobian with the predicted σ (:mod:`.design`) and the whole plan
(:mod:`.plan`). See ``docs/calibration_tour.md``.
"""

from __future__ import annotations

from cell.calibration.plan.capture_plan import (
    CALIBRATE_MARGIN_FRAC,
    CALIBRATE_OFFSETS,
    calibrate_plan_options,
    plan_cell_calibration,
)
from cell.calibration.plan.design import (
    design_rows,
    information_model,
    point_sensitivity,
    predict_sigmas,
)
from cell.calibration.plan.head_model import stereo_model
from cell.calibration.plan.orientations import orientation_figures
from cell.calibration.plan.plan import (
    CRITERIA,
    CalibrationPlanOptions,
    joint_range,
    plan_calibration,
)
from cell.calibration.plan.target import TargetGeometry, board_of, cell_target

__all__ = [
    "CALIBRATE_MARGIN_FRAC",
    "CALIBRATE_OFFSETS",
    "CRITERIA",
    "CalibrationPlanOptions",
    "TargetGeometry",
    "board_of",
    "calibrate_plan_options",
    "cell_target",
    "design_rows",
    "information_model",
    "joint_range",
    "orientation_figures",
    "plan_calibration",
    "plan_cell_calibration",
    "point_sensitivity",
    "predict_sigmas",
    "stereo_model",
]
