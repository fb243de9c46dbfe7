"""The survey tour: the survey's views (:func:`survey_views`) visited with the calibration
tour's machinery (:class:`planner.calibration.ViewTourPlanner`: the hole tour's GTSP, OMPL and
ruckig), so it is collision-free and jerk-limited.

Each view becomes one GTSP group: every collision-free IK solution of its TCP pose. A view the
arm cannot reach, or only in collision, is tried again turned about its view axis by 90°, -90°
and 180° (the same markers, seen from the same direction, with the wrist elsewhere); one that
still cannot be reached is left out and named; the survey's refusals (a marker in
fewer than 3 views, rays meeting at less than 20°, a network in pieces) then judge what remains.
Of the reachable views only the fewest that see every marker often enough from directions well
apart are driven (:mod:`cell.referencing.survey.select`). A stop's ``hole_id`` is the view's id.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from cell.config import CellConfig
from cell.referencing.errors import SurveyRefusedError
from cell.referencing.survey.plan import SurveyPlanOptions, survey_views
from cell.referencing.survey.select import SelectOptions, select_cell_views
from measure import StereoCalibration
from measure.head import head_frame
from planner import Options, Tour
from planner.calibration.tour import ViewTourPlanner
from planner.planner import ProgressCallback
from planner.viewpoints import HoleCandidates

Array = NDArray[np.float64]


#: the views driven by default: :class:`SelectOptions`' defaults
DEFAULT_SELECT = SelectOptions()

#: turns about the view axis tried, in this order, until the arm reaches the view (rad)
ROLLS_RAD = (0.0, np.pi / 2, -np.pi / 2, np.pi)


def _roll(angle: float) -> Array:
    c, s = np.cos(angle), np.sin(angle)
    T = np.eye(4)
    T[:2, :2] = [[c, -s], [s, c]]
    return T


@dataclass
class SurveyTour:
    """The timed tour through the reachable views; ``T_cell_left`` maps each view id to its
    planned left-camera pose (the prior of its markers' identification and the adjustment's
    start); ``left_out`` maps a view left out to the reason."""

    tour: Tour
    T_cell_left: dict[str, Array]
    left_out: dict[str, str] = field(default_factory=dict)
    #: where the plan came from when it was kept in a cache (the demo's), else empty
    plan_cache: str = ""


def _group(arm, vid: str, T_cell_tcp: Array) -> tuple[HoleCandidates | None, str]:
    result = arm.ik(T_cell_tcp)
    if not result.ok:
        return None, result.reason or "no IK solution"
    Q = np.asarray(result.solutions, dtype=float)
    branches = np.asarray(result.branches, dtype=np.int64)
    each = getattr(arm, "in_collision_each", None)
    hit = (np.asarray(each(Q), bool) if each is not None
           else np.array([arm.in_collision(q) for q in Q], bool))  # fmt: skip
    if hit.all():
        return None, "arm or head in collision"
    k = ~hit
    return HoleCandidates(vid, Q[k], branches[k], np.zeros(int(k.sum()), np.int64),
                          T_cell_tcp[None], None), ""  # fmt: skip


def plan_survey_tour(
    cell: CellConfig,
    stereo: StereoCalibration,
    plan: SurveyPlanOptions | None = None,
    options: Options | None = None,
    progress: ProgressCallback | None = None,
    select: SelectOptions | None = DEFAULT_SELECT,
) -> SurveyTour:
    """The survey tour of ``cell`` with head ``stereo`` (module doc); refused when no view is
    reachable. ``select``: of the reachable views, drive only those
    :func:`cell.referencing.survey.select.select_cell_views` chooses (None: all of them)."""
    arm = cell.build_arm()
    T_left_head = head_frame(stereo)  # the head (TCP) in the left camera frame
    groups, poses, left_out = [], {}, {}
    for vid, T_view in survey_views(cell, stereo, plan):
        for roll in ROLLS_RAD:
            T_cell_left = T_view @ _roll(roll)
            g, why = _group(arm, vid, T_cell_left @ T_left_head)
            if g is not None:
                groups.append(g)
                poses[vid] = T_cell_left
                break
        else:
            left_out[vid] = why
    if select is not None and groups:
        chosen = {vid for vid, _ in select_cell_views(cell, stereo, list(poses.items()), select)}
        groups = [g for g in groups if g.hole_id in chosen]
        poses = {vid: T for vid, T in poses.items() if vid in chosen}
    if not groups:
        raise SurveyRefusedError("survey tour", "no survey view is reachable without collision")
    tour = ViewTourPlanner(groups, options, progress).plan(cell)
    return SurveyTour(tour, poses, left_out)
