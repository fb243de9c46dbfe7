"""Refusing a thermal model (``thermal.json``) that does not belong to the cell it is run with.

A model is identified for one arm in one cell: its D-H table, base pose and tool are part of it.
Applied to another cell it would carry holes into the part frame through the wrong kinematics
without any sign of it, so the run refuses it and names the file and the field that differ:
``robot_model``, ``dh``, ``T_cell_base``, ``T_tool0_tcp`` against the cell file, and
``sensors.names`` (their count) against the temperatures the controller reports.
"""

from __future__ import annotations

import numpy as np

from cell.run.errors import ThermalModelMismatchError
from robots import Arm
from robots.thermal.model import ThermalModel

#: agreement of lengths (m) and of rotation-matrix and angle entries (rad) after a file round trip
ATOL = 1e-9


def _fmt(a: np.ndarray) -> str:
    return np.array2string(np.asarray(a, float), precision=6, separator=", ").replace("\n", "")


def check_model_for_cell(model: ThermalModel, arm: Arm, robot_model: str, where: str) -> None:
    """Refuse ``model`` unless its arm model, D-H table, base pose and tool are the cell's."""
    if model.robot_model != robot_model:
        raise ThermalModelMismatchError(where, "robot_model", repr(model.robot_model),
                                        repr(robot_model))  # fmt: skip
    for name, mine, cells in zip(("a_m", "d_m", "alpha_rad", "theta_offset_rad"),
                                 model.table.arrays(), arm.dh.arrays(), strict=True):  # fmt: skip
        if not np.allclose(mine, cells, rtol=0.0, atol=ATOL):
            raise ThermalModelMismatchError(where, f"dh.{name}", _fmt(mine), _fmt(cells))
    if model.table.joint_sign != arm.dh.joint_sign:
        raise ThermalModelMismatchError(where, "dh.joint_sign", _fmt(model.table.joint_sign),
                                        _fmt(arm.dh.joint_sign))  # fmt: skip
    for name, mine, cells in (("T_cell_base", model.T_cell_base, arm.T_cell_base),
                              ("T_tool0_tcp", model.T_tool0_tcp, arm.T_tool0_tcp)):  # fmt: skip
        if not np.allclose(mine, cells, rtol=0.0, atol=ATOL):
            raise ThermalModelMismatchError(where, name, _fmt(mine[:3, 3]) + " (xyz)",
                                            _fmt(cells[:3, 3]) + " (xyz)")  # fmt: skip


def check_model_sensors(model: ThermalModel, n_readings: int, where: str) -> None:
    """Refuse ``model`` unless it has one sensor per temperature the controller reports."""
    n_model = len(model.spec.sensor_names)
    if n_model != n_readings:
        raise ThermalModelMismatchError(
            where, "sensors.names", f"{n_model} sensors", f"{n_readings} (controller readings)"
        )
