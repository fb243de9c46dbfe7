"""One capture into one :class:`cell.run.results.HoleResult`: measure, carry into the part frame
through the (compensated) kinematics, compare with the nominal.

Frames: the measurement comes in the LEFT camera optical frame; ``T_head_left`` (the inverse of
:func:`measure.head_frame`) carries it into the head frame, which is the TCP;
``T_cell_tcp`` comes from the thermal model at the capture's joints and temperatures (or the
nominal kinematics without a model); ``T_cell_part`` from the cell file.
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np

from cell.config import CellConfig, HoleInCell
from cell.run.results import HoleResult, deviations
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
    that is not there (``missing``) or cannot be measured (``unmeasured``: a resume retries
    it)."""
    T_part_cell = invert(cell.T_cell_part())
    nominal = T_part_cell[:3, :3] @ hole.position_m + T_part_cell[:3, 3]
    base = _base_fields(hole, stop_index, nominal, q_rad, temps_c, sim_time_s)
    t0 = time.perf_counter()
    try:
        meas = measure_hole(
            left,
            right,
            stereo,
            expected_diameter_m=hole.diameter_m,
            expected_standoff_m=cell.tool.standoff_m,
        )
    except HoleNotFoundError as exc:
        return HoleResult(status="missing", reason=f"no hole found: {exc}", **base), None
    except MeasurementError as exc:
        return HoleResult(status="unmeasured", reason=f"not measurable: {exc}", **base), None
    t_meas = time.perf_counter() - t0
    T_head_left = invert(head_frame(stereo))
    T_part_left = T_part_cell @ T_cell_tcp(arm, model, q_rad, temps_c) @ T_head_left
    T_nom = T_part_cell @ arm.fk(q_rad, "tcp") @ T_head_left
    center_nominal_fk = T_nom[:3, :3] @ meas.center_m + T_nom[:3, 3]
    extra = {"center_part_uncompensated_m": [float(v) for v in center_nominal_fk]}
    return _measured(meas, T_part_left, hole, nominal, t_meas, extra, base), meas


def _base_fields(
    hole: HoleInCell,
    stop_index: int,
    nominal_part_m: np.ndarray,
    q_rad: np.ndarray,
    temps_c: np.ndarray,
    sim_time_s: float,
) -> dict[str, Any]:
    """The fields of a result that do not depend on the measurement."""
    return {
        "hole_id": hole.id,
        "stop_index": stop_index,
        "nominal_part_m": tuple(float(v) for v in nominal_part_m),
        "nominal_diameter_m": float(hole.diameter_m),
        "tolerance_m": hole.tolerance_m,
        "q_rad": tuple(float(v) for v in q_rad),
        "temperatures_c": tuple(float(v) for v in temps_c),
        "sim_time_s": float(sim_time_s),
    }


def _measured(
    meas: HoleMeasurement,
    T_part_left: np.ndarray,
    hole: HoleInCell,
    nominal_part_m: np.ndarray,
    measure_time_s: float,
    extra: dict[str, Any],
    base: dict[str, Any],
) -> HoleResult:
    """The result of a measured hole: centre and axis carried into the part frame by
    ``T_part_left``, deviations and the verdict against the tolerance; ``suspect`` flags a
    measurement of doubtful quality whatever the verdict."""
    center = T_part_left[:3, :3] @ meas.center_m + T_part_left[:3, 3]
    normal = T_part_left[:3, :3] @ meas.normal
    dpos, ddia, ok = deviations(center, meas.diameter_m, nominal_part_m, hole.diameter_m,
                                hole.tolerance_m)  # fmt: skip
    cov = np.asarray(meas.cov_center_radius, float)
    return HoleResult(
        status="suspect" if meas.status == "suspect" else ("ok" if ok else "fail"),
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
        measure_time_s=measure_time_s,
        extra=extra,
        **base,
    )
