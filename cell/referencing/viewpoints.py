"""The tour planner with the markers in view: of each hole's viewpoints (every roll about the
view axis the planner samples, and its tilted fallbacks), only those whose stop sees at least 4
well-spread reference markers in both cameras are kept; where none does, all are kept and the
hole is named (its stop will fall back to the arm). The tour's cost is otherwise the planner's.

The hole stays on the view axis: a lateral offset within the hole's image margin, which the
issue allows, is not used (every hole of the built-in layout sees 4 markers at every roll).
"""

from __future__ import annotations

import logging

import numpy as np
from numpy.typing import NDArray

from cell.config import CellConfig
from cell.config.markers import marker_in_cell
from cell.referencing.observations import project
from cell.referencing.visibility import seen, well_spread
from measure import StereoCalibration
from measure.head import head_frame
from planner import Options, TourPlanner
from planner.planner import ProgressCallback
from planner.protocols import ArmLike, CellLike
from planner.tour import LeftOut
from planner.viewpoints import HoleCandidates
from robots.transforms import invert

log = logging.getLogger(__name__)

Array = NDArray[np.float64]


def poses_seeing_markers(cell: CellConfig, stereo: StereoCalibration, T_cell_tcp: Array
                         ) -> NDArray[np.bool_]:  # fmt: skip
    """Mask (p,) of the TCP poses (p, 4, 4) whose stop sees at least 4 well-spread markers in
    both cameras."""
    T_cell_part = cell.T_cell_part()
    placed = [marker_in_cell(m, T_cell_part) for m in cell.reference_markers]
    P = np.array([p for p, _ in placed]).reshape(-1, 3)
    N = np.array([n for _, n in placed]).reshape(-1, 3)
    T_tcp_left = invert(head_frame(stereo))
    out = np.zeros(len(T_cell_tcp), bool)
    for k, T in enumerate(T_cell_tcp):
        T_left = T @ T_tcp_left
        mask = seen(stereo, T_left, P, N)
        if mask.sum() >= 4:
            out[k] = well_spread(stereo, project(stereo, "left", invert(T_left), P[mask]))
    return out


class MarkerAwarePlanner(TourPlanner):
    """A :class:`planner.TourPlanner` whose viewpoints see the markers (module doc)."""

    def __init__(
        self,
        cell: CellConfig,
        stereo: StereoCalibration,
        options: Options | None = None,
        progress: ProgressCallback | None = None,
    ) -> None:
        super().__init__(options, progress)
        self.marker_cell, self.stereo = cell, stereo
        self.without_markers: list[str] = []

    def _viewpoints(
        self, arm: ArmLike, cell: CellLike
    ) -> tuple[list[HoleCandidates], list[LeftOut]]:
        found, left = super()._viewpoints(arm, cell)
        if not self.marker_cell.reference_markers:
            return found, left
        out = []
        for c in found:
            ok = poses_seeing_markers(self.marker_cell, self.stereo, c.poses)[c.pose]
            if ok.any():
                c = HoleCandidates(c.hole_id, c.q[ok], c.branch[ok], c.pose[ok], c.poses, None)
            else:
                self.without_markers.append(c.hole_id)
                log.warning("hole %s: no viewpoint sees 4 well-spread markers; its stop will "
                            "fall back to the arm", c.hole_id)  # fmt: skip
            out.append(c)
        return out, left
