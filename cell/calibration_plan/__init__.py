"""The calibration tour of a cell (``holecell plan-calibration``): the cell's target and head as
the view planner takes them (:mod:`.target`, :mod:`.head_model`), the information-based design
on the cell calibration's own Jacobian with the predicted σ (:mod:`.design`) and the whole plan
(:mod:`.plan`). See ``docs/calibration_tour.md``.
"""

from cell.calibration_plan.plan import (
    CRITERIA,
    CalibrationPlanOptions,
    joint_range,
    plan_calibration,
)
from cell.calibration_plan.target import TargetGeometry, board_of, cell_target

__all__ = [
    "CRITERIA",
    "CalibrationPlanOptions",
    "TargetGeometry",
    "board_of",
    "cell_target",
    "joint_range",
    "plan_calibration",
]
