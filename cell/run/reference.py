"""The reference-target tour: the arm visits the cell's reference targets for the thermal update.

Each target is seen from several views (the thermal model's recommended pose plan,
:class:`robots.thermal.plan.ViewOptions`: the view axis tilted from the target normal toward
several azimuths), because one view per target leaves the length terms nearly inseparable
(``docs/thermal.md``). The planner plans a tour over these views exactly as over holes: each
view becomes a pseudo-hole ``"<target>#<view>"`` whose normal is the reversed view axis.
"""

from __future__ import annotations

import logging

import numpy as np

from cell.config import CellConfig, Hole
from cell.errors import CellError
from planner import Options, Tour, plan_tour
from robots.thermal.plan import ViewOptions, view_pose
from robots.transforms import invert

VIEW_SEPARATOR = "#"
#: the logger the planner reports left-out holes on
PLANNER_LOGGER = "planner.planner"
log = logging.getLogger(__name__)


def target_of(stop_id: str) -> str:
    """The reference target id of a reference-tour stop id (``"R1#2"`` -> ``"R1"``)."""
    return stop_id.split(VIEW_SEPARATOR, 1)[0]


def reference_cell(cell: CellConfig, views: ViewOptions | None = None) -> CellConfig:
    """A copy of ``cell`` whose part holes are the views of its reference targets (part frame)."""
    if not cell.reference_targets:
        raise CellError(f"cell {cell.name!r} has no reference_targets for the thermal update")
    views = views or ViewOptions()
    T_cell_base = cell.T_cell_base()
    T_base_cell, T_part_cell = invert(T_cell_base), invert(cell.T_cell_part())
    holes = []
    for r in cell.reference_targets:
        p_cell, n_cell = np.asarray(r.position, float), np.asarray(r.normal, float)
        p_base = T_base_cell[:3, :3] @ p_cell + T_base_cell[:3, 3]
        n_base = T_base_cell[:3, :3] @ n_cell
        for k, (tilt, az) in enumerate(zip(views.tilts_rad, views.azimuths_rad, strict=True)):
            z_base = view_pose(p_base, n_base, tilt, az, 0.0, cell.tool.standoff_m)[:3, 2]
            n_part = T_part_cell[:3, :3] @ (T_cell_base[:3, :3] @ -z_base)
            p_part = T_part_cell[:3, :3] @ p_cell + T_part_cell[:3, 3]
            holes.append(
                Hole(
                    id=f"{r.id}{VIEW_SEPARATOR}{k}",
                    position=p_part.tolist(),
                    normal=(n_part / np.linalg.norm(n_part)).tolist(),
                    diameter=r.diameter,
                )
            )
    part = cell.part.model_copy(update={"holes": holes})
    return cell.model_copy(update={"name": f"{cell.name}:reference", "part": part})


class _LeftOutViews(logging.Filter):
    """Holds back the planner's warnings about left-out holes while a reference tour is planned:
    views the arm cannot take are expected there (the tour lists them in ``left_out``)."""

    def filter(self, record: logging.LogRecord) -> bool:
        return "left out" not in record.getMessage()


def plan_reference_tour(
    cell: CellConfig, options: Options | None = None, views: ViewOptions | None = None
) -> Tour:
    """Plan the tour home -> every reachable view of every reference target -> home. Views
    left out (unreachable, in collision) are logged at INFO, not as warnings: the other views
    of the target serve."""
    planner_log, quiet = logging.getLogger(PLANNER_LOGGER), _LeftOutViews()
    planner_log.addFilter(quiet)
    try:
        tour = plan_tour(reference_cell(cell, views), options or Options())
    finally:
        planner_log.removeFilter(quiet)
    for h in tour.left_out:
        log.info("reference view %s left out: %s", h.hole_id, h.reason)
    return tour
