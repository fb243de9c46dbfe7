"""One capture into one :class:`cell.results.HoleResult`: measure, carry into the part frame
through the (compensated) kinematics, compare with the nominal.

Frames: the measurement comes in the LEFT camera optical frame; ``T_head_left`` (the inverse of
:func:`measure.head_frame`) carries it into the head frame, which is the TCP;
``T_cell_tcp`` comes from the thermal model at the capture's joints and temperatures (or the
nominal kinematics without a model); ``T_cell_part`` from the cell file.
"""

from __future__ import annotations

import time

import numpy as np

from cell.config import CellConfig, HoleInCell
from cell.results import HoleResult, deviations
from measure import HoleMeasurement, MeasurementError, StereoCalibration, head_frame, measure_hole
from measure.errors import HoleNotFoundError
from robots import Arm
from robots.thermal.compensate import compensated_T_cell_tcp
from robots.thermal.model import ThermalModel
from robots.transforms import invert


def T_cell_tcp(
    arm: Arm, model: ThermalModel | None, q_rad: np.ndarray, temps_c: np.ndarray
) -> np.ndarray:
    """TCP pose in the cell: compensated if a thermal model is given, nominal otherwise; always
    with the cell's base pose and tool (the model was checked against them when loaded)."""
    if model is None:
        return arm.fk(q_rad, "tcp")
    return compensated_T_cell_tcp(model, arm.T_cell_base, arm.T_tool0_tcp, q_rad, temps_c)


def inspect_hole(
    cell: CellConfig,
    arm: Arm,
    model: ThermalModel | None,
    stereo: StereoCalibration,
    hole: HoleInCell,
    stop_index: int,
    left: np.ndarray,
    right: np.ndarray,
    q_rad: np.ndarray,
    temps_c: np.ndarray,
    sim_time_s: float,
) -> tuple[HoleResult, HoleMeasurement | None]:
    """Measure ``hole`` from one pair and compare it with its nominal; never raises for a hole
    that is not there or cannot be measured (that is a result: ``missing``)."""
    T_part_cell = invert(cell.T_cell_part())
    nominal = T_part_cell[:3, :3] @ hole.position_m + T_part_cell[:3, 3]
    base = {
        "hole_id": hole.id,
        "stop_index": stop_index,
        "nominal_part_m": tuple(float(v) for v in nominal),
        "nominal_diameter_m": float(hole.diameter_m),
        "tolerance_m": hole.tolerance_m,
        "q_rad": tuple(float(v) for v in q_rad),
        "temperatures_c": tuple(float(v) for v in temps_c),
        "sim_time_s": float(sim_time_s),
    }
    t0 = time.perf_counter()
    try:
        meas = measure_hole(left, right, stereo, expected_diameter_m=hole.diameter_m)
    except MeasurementError as exc:
        kind = "no hole found" if isinstance(exc, HoleNotFoundError) else "not measurable"
        reason = f"{kind}: {exc}"
        return HoleResult(status="missing", reason=reason, **base), None
    t_meas = time.perf_counter() - t0
    T_head_left = invert(head_frame(stereo))
    T_part_left = T_part_cell @ T_cell_tcp(arm, model, q_rad, temps_c) @ T_head_left
    center = T_part_left[:3, :3] @ meas.center_m + T_part_left[:3, 3]
    normal = T_part_left[:3, :3] @ meas.normal
    T_nom = T_part_cell @ arm.fk(q_rad, "tcp") @ T_head_left
    center_nominal_fk = T_nom[:3, :3] @ meas.center_m + T_nom[:3, 3]
    dpos, ddia, ok = deviations(center, meas.diameter_m, nominal, hole.diameter_m, hole.tolerance_m)
    cov = np.asarray(meas.cov_center_radius, float)
    status = "suspect" if meas.status == "suspect" else ("ok" if ok else "fail")
    result = HoleResult(
        status=status,
        passed=ok,
        center_part_m=tuple(float(v) for v in center),
        normal_part=tuple(float(v) for v in normal),
        diameter_m=float(meas.diameter_m),
        position_deviation_m=dpos,
        diameter_deviation_m=ddia,
        u_center_m=float(np.sqrt(max(np.trace(cov[:3, :3]), 0.0))),
        u_diameter_m=float(2.0 * np.sqrt(max(cov[3, 3], 0.0))),
        rms_m=float(meas.rms_m),
        n_points=int(meas.n_points),
        measure_time_s=t_meas,
        extra={"center_part_uncompensated_m": [float(v) for v in center_nominal_fk]},
        **base,
    )
    return result, meas
