"""Plan the calibration tour of a cell: candidates → design → tour → ``caltour.json``.

1. Candidate views of the cell's calibration target (:func:`planner.calibration.candidate_views`):
   both cameras see the whole board at a good distance and tilt, IK within limits, no collision.
2. A geometric pre-selection (:func:`planner.calibration.preselect`), greedy, of ``views``
   views: large rotations about axes far from parallel, features over both whole images,
   joints over the range the hole tour uses (``joint_range``: its stops, widened by
   ``JOINT_RANGE_MARGIN_RAD``): the geometric design.
3. The design (``criterion``): ``"geometric"`` keeps that; ``"tcp"`` and ``"d"`` choose
   ``views`` of every candidate by the calibration adjustment's information
   (:mod:`cell.calibration.plan.design`: greedy and exchange, and exchange from the geometric
   design; the better wins). Every criterion predicts the parameters' σ.
4. The tour through them (:func:`planner.calibration.plan_view_tour`): the hole tour's GTSP,
   OMPL and ruckig machinery, so collision-free and jerk-limited.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from cell.calibration.plan.design import (
    CORNER_SIGMA_PX,
    design_rows,
    information_model,
    predict_sigmas,
)
from cell.calibration.plan.head_model import stereo_model
from cell.calibration.plan.orientations import orientation_figures
from cell.calibration.plan.target import TargetGeometry, board_of
from cell.config import CellConfig
from cell.errors import CellError
from cell.uncertainty.repeatability import repeatability_rp_m, sigma_per_axis_m
from measure import StereoCalibration
from planner import Options
from planner.calibration import (
    CalibrationTour,
    CandidateOptions,
    PreselectOptions,
    candidate_views,
    geometry_score,
    plan_view_tour,
    preselect,
    view_ids,
    view_metadata,
)
from planner.planner import ProgressCallback

#: the design criteria: geometric pre-selection only, I-optimal on the TCP, D-optimal
CRITERIA = ("geometric", "tcp", "d")
#: the hole tour's joint range is widened by this much each side (rad): a range of one value
#: (a joint that does not move in the tour) still has bins to fill
JOINT_RANGE_MARGIN_RAD = np.radians(10.0)


@dataclass(frozen=True)
class CalibrationPlanOptions:
    """Settings of :func:`plan_calibration`.

    ``views``: stations in the tour; ``criterion``: one of :data:`CRITERIA`; ``predict``:
    compute the predicted σ (needs the arm's D-H table; always on for "tcp" and "d");
    ``corner_sigma_px``: the corner noise per image axis of the design and the prediction (px);
    ``repeatability``: the arm's repeatability (the cell's RP) scatters each view's head pose in
    the design and the prediction; ``candidates`` / ``preselect``: the planner's sampling and
    pre-selection settings; ``tour``: the tour planner's :class:`planner.Options` (dwell, seed,
    resolution, ...).
    """

    views: int = 120
    criterion: str = "tcp"
    predict: bool = True
    corner_sigma_px: float = CORNER_SIGMA_PX
    repeatability: bool = True
    candidates: CandidateOptions = field(default_factory=CandidateOptions)
    preselect: PreselectOptions = field(default_factory=PreselectOptions)
    tour: Options = field(default_factory=Options)

    def __post_init__(self) -> None:
        if self.criterion not in CRITERIA:
            raise CellError(f"criterion {self.criterion!r}: expected one of {', '.join(CRITERIA)}")
        if self.views < 1:
            raise CellError(f"views {self.views}: at least one calibration view is needed")
        if not (self.corner_sigma_px > 0 and np.isfinite(self.corner_sigma_px)):
            raise CellError(f"corner_sigma_px {self.corner_sigma_px}: must be a positive number")


def joint_range(stops_q: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The joint range (lower, upper, rad) the hole tour's stops (S, 6) use, widened by
    :data:`JOINT_RANGE_MARGIN_RAD` each side."""
    Q = np.atleast_2d(np.asarray(stops_q, dtype=float))
    return Q.min(axis=0) - JOINT_RANGE_MARGIN_RAD, Q.max(axis=0) + JOINT_RANGE_MARGIN_RAD


def plan_calibration(
    cell: CellConfig,
    target: TargetGeometry,
    stereo: StereoCalibration,
    stops_q: NDArray[np.float64],
    options: CalibrationPlanOptions | None = None,
    progress: ProgressCallback | None = None,
) -> CalibrationTour:
    """The calibration tour of ``cell`` (module docstring). ``stops_q`` (S, 6, rad): the hole
    tour's stops, whose joint range the views should cover."""
    o = options or CalibrationPlanOptions()
    started = time.perf_counter()
    arm = cell.build_arm()
    board = board_of(target)
    head = stereo_model(stereo)
    t = time.perf_counter()
    cands = candidate_views(arm, board, head, cell.tool.standoff_m, cell.home_q(), o.candidates)
    timings = {"candidates": time.perf_counter() - t}
    if len(cands) < o.views:
        raise CellError(
            f"calibration_target: only {len(cands)} feasible view(s), {o.views} asked for; "
            "move the target where the arm sees it from more directions, or ask for fewer views"
        )
    box = joint_range(stops_q)
    t = time.perf_counter()
    geometric = preselect(cands, o.views, head.image_size, box, o.preselect)
    timings["preselect"] = time.perf_counter() - t
    t = time.perf_counter()
    if o.criterion == "geometric" and not o.predict:
        rows, prediction = geometric, {}
    else:
        rp_m, _ = repeatability_rp_m(cell.robot.model, cell.robot.repeatability_m)
        rep = sigma_per_axis_m(rp_m) if o.repeatability else 0.0
        model = information_model(cell, target, stereo, cands, stops_q, o.corner_sigma_px, rep)
        rows = (
            geometric
            if o.criterion == "geometric"
            else design_rows(model, o.views, o.criterion, [geometric])
        )
        prediction = predict_sigmas(model, rows)
    timings["design"] = time.perf_counter() - t
    chosen = cands.subset(rows)
    ids = view_ids(len(rows))
    tour = plan_view_tour(cell, chosen, ids, o.tour, progress)
    score = geometry_score(cands, list(rows), head.image_size, box, o.preselect)
    orientations, min_between = orientation_figures(cands.T_cell_tcp[list(rows), :3, :3])
    design = {
        "criterion": o.criterion,
        "candidates": len(cands),
        "refused": cands.refused,
        "rotation_share": score.rotation,
        "image_share": score.image,
        "joint_share": score.joints,
        "min_rotation_rad": score.min_rotation_rad,
        "orientations": orientations,
        "min_rotation_between_orientations_rad": min_between,
        "axis_eigen_min": score.axis_eigen_min,
        "joint_range_rad": [box[0].tolist(), box[1].tolist()],
        "timings_s": timings,
    }
    tour.planning_time_s = time.perf_counter() - started
    tour.timings_s = {**timings, **tour.timings_s}
    return CalibrationTour(tour, target.to_dict(), view_metadata(chosen, ids), design, prediction)
