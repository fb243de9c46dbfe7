"""The reference-target tour: the arm visits the cell's reference targets for the thermal update.

The views are the reference plan designed for the tour (:mod:`robots.thermal.design`): among
every reachable, collision-free view of every target, those that minimise the thermal model's
predicted error at the tour's stops (the hole tour's joint vectors when a tour is given, else
each hole's collision-free viewpoint configuration nearest home). ``holecell thermal
plan-views`` prints and writes the same plan (:func:`design_reference_plan`). The planner plans a
tour through exactly these joint vectors: each view becomes a pseudo-hole ``"<target>#<view>"``
(normal: the reversed view axis) whose only candidate is the designed configuration.
"""

from __future__ import annotations

import logging
from dataclasses import replace

import numpy as np
from numpy.typing import NDArray

from cell.config import CellConfig, Hole
from cell.config.tours import hole_stops
from cell.errors import CellError
from planner import Options, Tour, TourPlanner
from planner.protocols import ArmLike, CellLike
from planner.tour import LeftOut
from planner.viewpoints import HoleCandidates
from robots.thermal.design import Design, DesignOptions, candidate_views, design_views
from robots.thermal.errors import ThermalError
from robots.thermal.plan import view_plan
from robots.transforms import invert

VIEW_SEPARATOR = "#"
#: the logger the planner reports left-out holes on
PLANNER_LOGGER = "planner.planner"
log = logging.getLogger(__name__)


def target_of(stop_id: str) -> str:
    """The reference target id of a reference-tour stop id (``"R1#2"`` -> ``"R1"``)."""
    return stop_id.split(VIEW_SEPARATOR, 1)[0]


def design_reference_plan(
    cell: CellConfig,
    stops_q: NDArray[np.float64] | None = None,
    options: DesignOptions | None = None,
) -> Design:
    """The reference views designed for the stops ``stops_q`` (S, 6) rad (default
    :func:`hole_stops`), under the cell's reach and collision; raises :class:`CellError` when
    the cell has no reference target or none can be seen."""
    if not cell.reference_targets:
        raise CellError(f"cell {cell.name!r} has no reference_targets for the thermal update")
    arm = cell.build_arm()
    targets = {r.id: (r.position, r.normal) for r in cell.reference_targets}
    stops = hole_stops(cell)[1] if stops_q is None else np.atleast_2d(np.asarray(stops_q, float))
    cands, skipped = candidate_views(
        arm.dh, arm.lower, arm.upper, cell.T_cell_base(), cell.T_tool0_tcp(), targets,
        cell.tool.standoff_m, options, accept=lambda q: not arm.in_collision(q),
        rest_q=cell.home_q(),
    )  # fmt: skip
    try:
        design = design_views(
            arm.dh, cell.T_cell_base(), cell.T_tool0_tcp(), cands, stops, options,
            n_targets=len(targets),
        )  # fmt: skip
    except ThermalError as exc:
        why = "; ".join(f"{t}: {r}" for t, r in skipped.items())
        raise CellError(f"cell {cell.name!r}: {exc}" + (f" ({why})" if why else "")) from exc
    return replace(design, skipped=skipped)


def fixed_reference_plan(cell: CellConfig) -> list[tuple[str, NDArray[np.float64]]]:
    """(target id, joint vector rad) of the fixed recommended plan, three views per reference
    target (:func:`robots.thermal.plan.view_plan`'s defaults) under the cell's reach and
    collision: the plan the designed one is compared with."""
    arm = cell.build_arm()
    targets = {r.id: (r.position, r.normal) for r in cell.reference_targets}
    plan = view_plan(
        arm.dh, arm.lower, arm.upper, cell.T_cell_base(), cell.T_tool0_tcp(), targets,
        cell.tool.standoff_m, accept=lambda q: not arm.in_collision(q),
    )  # fmt: skip
    return plan.poses


def reference_cell(cell: CellConfig, design: Design) -> CellConfig:
    """A copy of ``cell`` whose part holes are the designed views (pseudo-holes, part frame)."""
    arm = cell.build_arm()
    T_part_cell = invert(cell.T_cell_part())
    holes = []
    for k, view in enumerate(design.views):
        target = next(r for r in cell.reference_targets if r.id == view.target_id)
        z_cell = arm.fk(view.q_rad, "tcp")[:3, 2]
        n_part = T_part_cell[:3, :3] @ -z_cell
        p_part = T_part_cell[:3, :3] @ np.asarray(target.position, float) + T_part_cell[:3, 3]
        holes.append(
            Hole(
                id=f"{view.target_id}{VIEW_SEPARATOR}{k}",
                position=p_part.tolist(),
                normal=(n_part / np.linalg.norm(n_part)).tolist(),
                diameter=target.diameter,
            )
        )
    part = cell.part.model_copy(update={"holes": holes})
    return cell.model_copy(update={"name": f"{cell.name}:reference", "part": part})


class _DesignedViewsPlanner(TourPlanner):
    """The tour planner with each pseudo-hole's only candidate the designed joint vector."""

    def __init__(self, options: Options, design: Design) -> None:
        super().__init__(options)
        self.design = design

    def _viewpoints(
        self, arm: ArmLike, cell: CellLike
    ) -> tuple[list[HoleCandidates], list[LeftOut]]:
        found = []
        for hole, view in zip(cell.holes_in_cell(), self.design.views, strict=True):
            q = np.asarray(view.q_rad, float).reshape(1, 6)
            found.append(
                HoleCandidates(hole.id, q, np.zeros(1, np.int64), np.zeros(1, np.int64),
                               arm.fk(q[0], "tcp")[None], None)
            )  # fmt: skip
        return found, []


def plan_reference_tour(
    cell: CellConfig,
    options: Options | None = None,
    tour: Tour | None = None,
    design: Design | None = None,
) -> Tour:
    """Plan the tour home -> every designed reference view -> home. The views are ``design``,
    else :func:`design_reference_plan` for the stops of ``tour`` (else the holes')."""
    if design is None:
        stops = None if tour is None else np.array([s.q for s in tour.stops], float)
        design = design_reference_plan(cell, stops)
    for tid, reason in design.skipped.items():
        log.info("reference target %s has no view: %s", tid, reason)
    log.info(
        "reference plan: %d views designed for %d stops, predicted %.2f um RMS at them",
        len(design.views), len(design.stop_sigma_m), design.predicted_rms_m * 1e6,
    )  # fmt: skip
    return _DesignedViewsPlanner(options or Options(), design).plan(reference_cell(cell, design))
