"""The simulated cell's truth as the cell calibration estimates it: for tests and benchmarks.

The calibration sees the arm only relative to its target, so the truth is put in the
calibration's gauge (:func:`robots.calibration.redundancy.fold_redundant`): the D-H terms the
table's shape makes redundant move into the target's pose and the hand-eye. The D-H table is
the true one at a simulation time (the thermal drift included: the calibration measures the
arm as it is during its tour). Never for the runner.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from cell.calibration.estimate import CellCalibration, State
from cell.sim.true_geometry import TrueGeometry
from robots.calibration import fk_with_errors
from robots.calibration.redundancy import fold_redundant
from robots.dh import DHTable
from robots.transforms import invert

Array = NDArray[np.float64]


def true_delta(nominal: DHTable, geometry: TrueGeometry, t_s: float) -> Array:
    """The true D-H errors (24,) against ``nominal`` at simulation time ``t_s`` (drift in)."""
    table = geometry.drift.table_at(geometry.drift_offset_s + t_s)
    a0, d0, al0, th0 = nominal.arrays()
    a, d, al, th = table.arrays()
    return np.stack([a - a0, d - d0, al - al0, th - th0], axis=1).reshape(-1)


def true_state(
    nominal: DHTable, geometry: TrueGeometry, T_left_right: Array | None, t_s: float
) -> State:
    """The truth in the calibration's unknowns and gauge at simulation time ``t_s``;
    ``T_left_right``: the true head's right camera in its left one."""
    delta, C, E = fold_redundant(nominal, true_delta(nominal, geometry, t_s))
    T_base_target = invert(geometry.T_cell_base) @ geometry.T_cell_target
    return State(
        T_tool0_camera=E @ geometry.T_tool0_camera_left,
        T_base_target=invert(C) @ T_base_target,
        T_left_right=T_left_right,
        delta=delta,
    )


def tcp_errors_m(
    nominal: DHTable,
    truth: State,
    T_tool0_camera: Array,
    delta: ArrayLike,
    T_camera_point: Array,
    q_rad: Array,
) -> Array:
    """Position error (V,) (m) at joints ``q_rad`` (V, 6) of a point fixed in the left camera
    (``T_camera_point``: 4x4, e.g. the TCP), model (``T_tool0_camera``, ``delta``) minus truth,
    both in the calibration's ``base_link``."""
    p = T_camera_point[:, 3]
    model = fk_with_errors(nominal, np.asarray(delta, float), q_rad) @ T_tool0_camera @ p
    true = fk_with_errors(nominal, truth.delta, q_rad) @ truth.T_tool0_camera @ p
    return np.linalg.norm(model[..., :3] - true[..., :3], axis=-1)


def calibration_tcp_errors_m(
    cal: CellCalibration, truth: State, T_camera_point: Array, q_rad: Array
) -> Array:
    """:func:`tcp_errors_m` of a calibration (its hand-eye and D-H errors)."""
    return tcp_errors_m(
        cal.nominal_dh, truth, cal.T_tool0_camera.T, cal.delta, T_camera_point, q_rad
    )
