"""The calibration tour: the chosen views visited with the hole tour's machinery, and its file.

:func:`plan_view_tour` hands the chosen views to :class:`planner.TourPlanner` in place of the
holes' viewpoints: each view is one GTSP group (its arm geometry's 2π variants), so the order,
the collision-free paths (straight, roadmap or OMPL) and the jerk-limited ruckig timing are the
hole tour's. A stop's ``hole_id`` is the view's id.

``caltour.json`` is ``tour.json`` (:mod:`planner.tour`, every field, read by the same code) with
``"format": "holecell.caltour"`` and one more mapping, ``calibration``: the board (``target``),
each view's metadata (``views``: the board's pose in both cameras, the features' image
coverage, the tilt), the design's figures (``design``) and the predicted σ of each calibration
parameter (``prediction``). SI units: m, rad, s; poses ``{xyz, quat_xyzw}``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from planner.calibration.candidates import Candidates
from planner.errors import TourFileError
from planner.options import Options
from planner.planner import ProgressCallback, TourPlanner
from planner.protocols import ArmLike, CellLike
from planner.tour import FORMAT as TOUR_FORMAT
from planner.tour import FORMAT_VERSION as TOUR_VERSION
from planner.tour import LeftOut, Tour, pose_dict, read_json_object, tour_from_dict, write_json
from planner.viewpoints import HoleCandidates

FORMAT = "holecell.caltour"
FORMAT_VERSION = 1


def view_ids(n: int) -> list[str]:
    """The views' ids, ``CAL01`` .. in the order they were chosen."""
    return [f"CAL{k + 1:02d}" for k in range(n)]


def view_groups(views: Candidates, ids: list[str]) -> list[HoleCandidates]:
    """One GTSP group per view: its configurations (2π variants), one pose."""
    return [
        HoleCandidates(
            hole_id=vid,
            q=np.asarray(views.variants[k], dtype=float),
            branch=np.full(len(views.variants[k]), int(views.branch[k]), dtype=np.int64),
            pose=np.zeros(len(views.variants[k]), dtype=np.int64),
            poses=views.T_cell_tcp[k][None],
            reason=None,
        )
        for k, vid in enumerate(ids)
    ]


class ViewTourPlanner(TourPlanner):
    """A :class:`TourPlanner` whose stops are given views, not the cell's holes."""

    def __init__(
        self,
        groups: list[HoleCandidates],
        options: Options | None = None,
        progress: ProgressCallback | None = None,
    ) -> None:
        super().__init__(options, progress)
        self.groups = list(groups)

    def _viewpoints(
        self, arm: ArmLike, cell: CellLike
    ) -> tuple[list[HoleCandidates], list[LeftOut]]:
        self.progress("viewpoints", len(self.groups), len(self.groups))
        return list(self.groups), []


def plan_view_tour(
    cell: CellLike,
    views: Candidates,
    ids: list[str],
    options: Options | None = None,
    progress: ProgressCallback | None = None,
) -> Tour:
    """The timed, collision-free tour home → every view → home (module docstring)."""
    return ViewTourPlanner(view_groups(views, ids), options, progress).plan(cell)


def view_metadata(views: Candidates, ids: list[str]) -> list[dict[str, Any]]:
    """Each view's metadata as written to ``caltour.json`` (``calibration.views``)."""
    out = []
    for k, vid in enumerate(ids):
        T_lt = views.T_left_target[k]
        out.append(
            {
                "id": vid,
                "tcp_pose": pose_dict(views.T_cell_tcp[k]),
                "T_left_target": pose_dict(T_lt),
                "T_right_target": pose_dict(views.T_right_target[k]),
                "distance_m": float(np.linalg.norm(T_lt[:3, 3])),
                "tilt_rad": float(views.tilt_rad[k]),
                "coverage_left": float(views.coverage[k, 0]),
                "coverage_right": float(views.coverage[k, 1]),
                "branch": int(views.branch[k]),
            }
        )
    return out


@dataclass
class CalibrationTour:
    """A calibration tour: the timed :class:`Tour` and the ``calibration`` mapping."""

    tour: Tour
    target: dict[str, Any]
    views: list[dict[str, Any]]
    design: dict[str, Any] = field(default_factory=dict)
    prediction: dict[str, Any] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        """The JSON-ready mapping of ``caltour.json``."""
        data = self.tour.to_dict()
        data["format"], data["version"] = FORMAT, FORMAT_VERSION
        data["calibration"] = {
            "target": self.target,
            "views": self.views,
            "design": self.design,
            "prediction": self.prediction,
        }
        return data

    def save(self, path: str | Path) -> Path:
        """Write ``caltour.json`` via a temporary name (an existing file is never half-written)."""
        return write_json(path, self.to_dict())


def caltour_from_dict(data: dict[str, Any], where: str = "<caltour>") -> CalibrationTour:
    """Rebuild a :class:`CalibrationTour`; errors name ``where`` and the field."""
    if data.get("format") != FORMAT:
        raise TourFileError(where, "format", f"expected {FORMAT!r}, got {data.get('format')!r}")
    if data.get("version") != FORMAT_VERSION:
        raise TourFileError(where, "version", f"unsupported version {data.get('version')!r}")
    cal = data.get("calibration")
    if not isinstance(cal, dict):
        raise TourFileError(where, "calibration", "missing or not a mapping")
    for key, kind in (("target", dict), ("views", list), ("design", dict), ("prediction", dict)):
        if not isinstance(cal.get(key), kind):
            raise TourFileError(where, f"calibration.{key}", f"missing or not a {kind.__name__}")
    tour = tour_from_dict(data | {"format": TOUR_FORMAT, "version": TOUR_VERSION}, where)
    ids = [v.get("id") if isinstance(v, dict) else None for v in cal["views"]]
    if sorted(map(str, ids)) != sorted(s.hole_id for s in tour.stops):
        raise TourFileError(where, "calibration.views", "the views do not match the tour's stops")
    return CalibrationTour(tour, cal["target"], cal["views"], cal["design"], cal["prediction"])


def load_caltour(path: str | Path) -> CalibrationTour:
    """Read ``caltour.json``; a missing or malformed file raises :class:`TourFileError`."""
    return caltour_from_dict(read_json_object(path), str(Path(path)))
