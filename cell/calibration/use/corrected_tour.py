"""The commanded poses under a calibration: each stop's joints corrected so the calibrated
model puts the head where the plan wanted it.

The tour was planned on the nominal kinematics (the cell file's base, D-H table and tool): a
stop's goal is ``T_cell_tcp = arm.fk(q_planned)``. Under the calibration the same joints put
the head elsewhere (a millimetre or so); :func:`correct_tour` finds, per stop, the joints
``q`` with ``geometry.fk(q) = arm.fk(q_planned)`` by damped Gauss-Newton steps on the
calibrated forward kinematics from the planned joints
(:func:`robots.thermal.compensate.solve_tcp`), and refuses a stop whose corrected joints leave
the arm's limits or do not converge.

The trajectory between two stops is moved by the corrections blended with a quintic
smoothstep (zero velocity and acceleration change at both ends, where the arm rests), constant
over each dwell, zero at home: the motion's shape is kept and the corrections are a few mrad,
far inside the clearances the planner kept. Home is not moved.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from itertools import pairwise

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from cell.calibration.errors import StopCorrectionError
from cell.calibration.use.run_calibration import RunGeometry
from cell.errors import CellError
from planner import Tour
from robots import Arm
from robots.thermal.compensate import CommandOptions, solve_tcp
from robots.transforms import invert

Array = NDArray[np.float64]

#: a corrected stop must reach its goal this closely (m, rad)
POSITION_TOL_M = 1e-9
ROTATION_TOL_RAD = 1e-9


@dataclass(frozen=True)
class Correction:
    """Per stop: the joint correction (rad) and how far the uncorrected head was off (m, rad)."""

    dq_rad: Array
    offset_m: Array
    offset_rad: Array


def corrected_joints(arm: Arm, geometry: RunGeometry, q_planned: Array) -> tuple[Array, str]:
    """The joints putting the calibrated TCP at ``arm.fk(q_planned)``; ``""`` or a reason."""
    T_goal_base = invert(geometry.T_cell_base) @ arm.fk(q_planned, "tcp")
    opts = CommandOptions(POSITION_TOL_M, ROTATION_TOL_RAD, max_iterations=20)
    res = solve_tcp(geometry.dh, T_goal_base, q_planned, geometry.T_tool0_tcp, opts)
    if not res.ok:
        return res.q_rad, (f"the calibrated kinematics do not reach the planned pose "
                           f"({res.position_error_m * 1e6:.3f} um off)")  # fmt: skip
    if not arm.within_limits(res.q_rad):
        bad = np.flatnonzero((res.q_rad < arm.lower) | (res.q_rad > arm.upper))
        j = int(bad[0]) if len(bad) else 0
        return res.q_rad, (
            f"the corrected joint {arm.joint_names[j]} = {res.q_rad[j]:.6f} rad leaves its "
            f"limits [{arm.lower[j]:.6f}, {arm.upper[j]:.6f}]: plan the tour again")  # fmt: skip
    return res.q_rad, ""


def _smoothstep(s: Array) -> Array:
    return s * s * s * (10.0 + s * (-15.0 + 6.0 * s))


def correct_tour(
    tour: Tour, arm: Arm, geometry: RunGeometry, where: str = "tour"
) -> tuple[Tour, list[Correction]]:
    """``tour`` with every stop's joints corrected for ``geometry`` (unchanged without a
    calibration); raises :class:`StopCorrectionError` naming the stop."""
    if not geometry.calibrated or not tour.stops:
        return tour, []
    traj = np.array(tour.trajectory, float)
    n = len(traj)
    keys: list[tuple[int, Array]] = [(0, np.zeros(6))]
    stops, out = [], []
    for k, s in enumerate(tour.stops):
        q0 = np.asarray(s.q, float)
        q1, why = corrected_joints(arm, geometry, q0)
        if why:
            raise StopCorrectionError(where, k, s.hole_id, why)
        dq = q1 - q0
        T_plan, T_was = arm.fk(q0, "tcp"), geometry.fk(q0, "tcp")
        rot = Rotation.from_matrix(T_plan[:3, :3] @ T_was[:3, :3].T).as_rotvec()
        out.append(Correction(dq, T_plan[:3, 3] - T_was[:3, 3], rot))
        r0 = round(s.t / tour.dt)
        r1 = min(round((s.t + s.dwell_s) / tour.dt), n - 1)
        keys += [(r0, dq), (r1, dq)]
        stops.append(replace(s, q=tuple(float(v) for v in q1)))
    keys.append((n - 1, np.zeros(6)))
    corr = np.zeros_like(traj)
    for (ra, da), (rb, db) in pairwise(keys):
        if rb < ra:
            raise CellError(f"{where}: stops out of time order at trajectory row {ra}")
        rows = np.arange(ra, rb + 1)
        w = _smoothstep((rows - ra) / max(rb - ra, 1))
        corr[rows] = da + np.outer(w, db - da)
    traj += corr
    for s in stops:  # the stops exactly as corrected
        r0 = round(s.t / tour.dt)
        r1 = min(round((s.t + s.dwell_s) / tour.dt), n - 1)
        traj[r0 : r1 + 1] = np.asarray(s.q, float)
    bad = ~np.all((traj >= arm.lower - 1e-9) & (traj <= arm.upper + 1e-9), axis=1)
    if bad.any():
        r = int(np.flatnonzero(bad)[0])
        raise CellError(f"{where}: the corrected trajectory leaves the joint limits at row {r} "
                        f"(t = {r * tour.dt:.3f} s): plan the tour again")  # fmt: skip
    return replace(tour, stops=stops, trajectory=traj), out
