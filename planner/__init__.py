"""Inspection tour planning: viewpoints, sequencing, collision-free paths, timing.

Entry point: :func:`plan_tour` (or :class:`TourPlanner`) with :class:`Options`;
the result is a :class:`Tour`, written and read as ``tour.json``.
"""

from planner.errors import (
    NoReachableHoleError,
    PlanningError,
    SegmentPlanningError,
    StartConfigurationError,
    TourCellMismatchError,
    TourFileError,
    UnreachableHoleError,
)
from planner.options import Options
from planner.planner import STAGES, TourPlanner, cell_sha256, check_tour_for_cell, plan_tour
from planner.tour import LeftOut, Stop, Tour, load_tour

__all__ = [
    "STAGES",
    "LeftOut",
    "NoReachableHoleError",
    "Options",
    "PlanningError",
    "SegmentPlanningError",
    "StartConfigurationError",
    "Stop",
    "Tour",
    "TourCellMismatchError",
    "TourFileError",
    "TourPlanner",
    "UnreachableHoleError",
    "cell_sha256",
    "check_tour_for_cell",
    "load_tour",
    "plan_tour",
]
