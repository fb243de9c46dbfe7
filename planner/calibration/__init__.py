"""Calibration tours: views of the calibration board chosen by experimental design.

:func:`candidate_views` samples every feasible view (both cameras see the whole board at a good
distance and tilt, IK within limits, no collision); :func:`preselect` chooses a geometrically
diverse set (large rotations about axes far from parallel, features over the whole image, joints
over the hole tour's range); :func:`choose_by_information` chooses by the calibration's Fisher
information (I- or D-optimal); :func:`plan_view_tour` orders and times them with the hole tour's
GTSP, OMPL and ruckig machinery; :class:`CalibrationTour` is ``caltour.json``. Inputs are plain
(:class:`Board`, :class:`StereoModel`): the cell side builds them from its config.
"""

from planner.calibration.board import Board, Projector, StereoModel
from planner.calibration.candidates import CandidateOptions, Candidates, candidate_views
from planner.calibration.select import (
    GeometryScore,
    PreselectOptions,
    choose_by_information,
    geometry_score,
    preselect,
)
from planner.calibration.tour import (
    CalibrationTour,
    ViewTourPlanner,
    caltour_from_dict,
    load_caltour,
    plan_view_tour,
    view_ids,
    view_metadata,
)
from planner.errors import NoCalibrationViewError
from robots.design import design_value

__all__ = [
    "Board",
    "CalibrationTour",
    "CandidateOptions",
    "Candidates",
    "GeometryScore",
    "NoCalibrationViewError",
    "PreselectOptions",
    "Projector",
    "StereoModel",
    "ViewTourPlanner",
    "caltour_from_dict",
    "candidate_views",
    "choose_by_information",
    "design_value",
    "geometry_score",
    "load_caltour",
    "plan_view_tour",
    "preselect",
    "view_ids",
    "view_metadata",
]
