"""The calibration tour ``holecell calibrate cell`` plans when it is given none.

The same plan as ``holecell plan-calibration`` (:func:`cell.calibration.plan.plan_calibration`,
the hole tour's joint range from each hole's viewpoint nearest home), with the candidates'
sideways offsets halved (:data:`CALIBRATE_OFFSETS`): the board then stays on the head's view
axis and well inside both images when the uncalibrated cell is a few millimetres off (the
head's mount, the base, the target's placement, the D-H errors), so no view loses it.
"""

from __future__ import annotations

import gc
from dataclasses import replace

from cell.calibration.plan.plan import CalibrationPlanOptions, plan_calibration
from cell.calibration.plan.target import cell_target
from cell.config import CellConfig
from measure import StereoCalibration
from planner import Options
from planner.calibration import CalibrationTour, CandidateOptions
from planner.planner import ProgressCallback

#: sideways offsets of the candidate views (x standoff): half of plan-calibration's default.
#: With the full 0.1 x standoff diagonal offsets a 50 deg tilted view meets the board 55 mm
#: from its centre, past the plate's edge for the 9 x 6 board of the built-in cell (the
#: board then sits near the image border, where a few millimetres of error can cut it off).
CALIBRATE_OFFSETS = ((0.0, 0.0), (0.05, 0.05), (-0.05, 0.05), (0.05, -0.05), (-0.05, -0.05))
#: the features stay this share of the image width inside its border in both cameras
CALIBRATE_MARGIN_FRAC = 0.04


def calibrate_plan_options(
    views: int = CalibrationPlanOptions().views, seed: int = 0, dwell_s: float | None = None
) -> CalibrationPlanOptions:
    """Plan options of ``calibrate cell``: ``views`` views, the tour's ``seed`` and dwell."""
    cand = replace(CandidateOptions(), offsets=CALIBRATE_OFFSETS, margin_frac=CALIBRATE_MARGIN_FRAC)
    tour = Options(seed=seed) if dwell_s is None else Options(seed=seed, dwell_s=dwell_s)
    return CalibrationPlanOptions(views=views, candidates=cand, tour=tour)


def plan_cell_calibration(
    cell: CellConfig,
    stereo: StereoCalibration,
    options: CalibrationPlanOptions | None = None,
    progress: ProgressCallback | None = None,
) -> CalibrationTour:
    """The calibration tour of ``cell`` (module docstring)."""
    from cell.config.tours import hole_stops

    o = options or calibrate_plan_options()
    cal = plan_calibration(cell, cell_target(cell), stereo, hole_stops(cell)[1], o, progress)
    gc.collect()  # free the OMPL objects now (their bindings complain if still alive at exit)
    return cal
