"""A tour against the cell it is run in: whether a tour belongs to the cell (:func:`check_tour`),
the trajectory row of each stop (:func:`stop_rows`), and stand-in stops when no tour is given
(:func:`hole_stops`, each hole's collision-free viewpoint nearest home)."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from cell.config.schema import CellConfig
from cell.errors import CellError, TourMismatchError
from planner import Tour, TourCellMismatchError, check_tour_for_cell
from planner.viewpoints import hole_candidates
from robots.models import JOINT_NAMES, MODELS


def stop_rows(tour: Tour) -> list[int]:
    """Trajectory row of every stop (arrival time / dt), checked against the stop's joints."""
    rows = []
    for k, s in enumerate(tour.stops):
        r = round(s.t / tour.dt)
        if not 0 <= r < len(tour.trajectory) or not np.allclose(tour.trajectory[r], s.q, atol=1e-6):
            raise CellError(f"tour: stop {k} ({s.hole_id}) is not on the trajectory at t={s.t}")
        rows.append(r)
    return rows


def check_tour(tour: Tour, cell: CellConfig, where: str, reference: bool = False) -> None:
    """Refuse a tour not made for ``cell`` (:func:`planner.check_tour_for_cell`: robot model, cell
    name, SHA-256 of the cell file text; here also joint names, trajectory shape, stops on the
    trajectory, known holes, no hole visited twice). Reference tours are checked for the robot
    only."""
    if reference:
        if tour.robot_model != cell.robot.model:
            raise TourMismatchError(where, "robot model", tour.robot_model, cell.robot.model)
    else:
        try:
            check_tour_for_cell(tour, cell)
        except TourCellMismatchError as exc:
            raise TourMismatchError(where, exc.field, exc.tour_value, exc.cell_value) from exc
    names = JOINT_NAMES if cell.robot.model in MODELS else cell.build_robot().joint_names
    if tuple(tour.joint_names) != tuple(names):
        raise TourMismatchError(where, "robot.joint_names", tour.joint_names, names)
    traj = np.asarray(tour.trajectory)
    if traj.ndim != 2 or traj.shape[1] != 6 or len(traj) < 2:
        raise CellError(f"{where}: trajectory has shape {traj.shape}, expected (N >= 2, 6)")
    ids = [s.hole_id for s in tour.stops]
    repeated = sorted({h for h in ids if ids.count(h) > 1})
    if repeated:
        raise CellError(f"{where}: stops[].hole_id: holes visited more than once: {repeated[:5]}")
    if not reference:
        known = {h.id for h in cell.part.holes}
        unknown = [s.hole_id for s in tour.stops if s.hole_id not in known]
        if unknown:
            raise CellError(f"{where}: stops.hole_id: holes the cell does not have: {unknown[:5]}")
    stop_rows(tour)


def hole_stops(
    cell: CellConfig, roll_step_deg: float = 15.0
) -> tuple[list[str], NDArray[np.float64]]:
    """Stand-in stops when no tour is given: hole ids and (S, 6) rad, per hole its
    collision-free viewpoint configuration nearest home (the planner's candidates). Holes the
    arm cannot see are left out."""
    arm, home = cell.build_arm(), cell.home_q()
    ids, out = [], []
    for hole in cell.holes_in_cell():
        c = hole_candidates(arm, hole, cell.tool.standoff_m, roll_step_deg)
        if c.ok:
            ids.append(hole.id)
            out.append(c.q[np.argmin(np.abs(c.q - home).sum(axis=1))])
    if not out:
        raise CellError(
            f"cell {cell.name!r}: no hole is reachable to design the reference plan for"
        )
    return ids, np.array(out)
