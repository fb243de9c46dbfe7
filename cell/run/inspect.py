"""One capture into one :class:`cell.records.hole_result.HoleResult`: measure, carry into the part
frame through the (compensated) kinematics, compare with the nominal.

Frames: the measurement comes in the LEFT camera optical frame; ``T_head_left`` (the inverse of
:func:`measure.head_frame`) carries it into the head frame, which is the TCP;
``T_cell_tcp`` comes from the thermal model at the capture's joints and temperatures (or the
nominal kinematics without a model); ``T_cell_part`` from the cell file. The centre and diameter
are then corrected to 20 degC
(:mod:`cell.uncertainty.part_temperature`), the budget is formed
(:mod:`cell.uncertainty.budget`) and the decision taken (:mod:`cell.uncertainty.decision`).
"""

from __future__ import annotations

import time
from dataclasses import replace
from typing import Any

import numpy as np

from cell.calibration.use import RunGeometry
from cell.config import CellConfig, HoleInCell
from cell.gdt.montecarlo import gdt_extra
from cell.records.hole_result import HoleResult, deviations
from cell.run.referenced import (
    HeadInputs,
    LocatedStop,
    referenced_contributions,
    survey_markers_factor,
)
from cell.uncertainty.budget import combine
from cell.uncertainty.context import BudgetContext, budget_context, hole_contributions
from cell.uncertainty.decision import decide_hole, decide_one
from measure import HoleMeasurement, MeasurementError, StereoCalibration, head_frame, measure_hole
from measure.errors import HoleNotFoundError
from robots import Arm
from robots.thermal.compensate import compensated_T_cell_tcp
from robots.thermal.model import ThermalModel
from robots.transforms import invert


def T_cell_tcp(
    arm: Arm | RunGeometry, model: ThermalModel | None, q_rad: np.ndarray, temps_c: np.ndarray
) -> np.ndarray:
    """TCP pose in the cell: compensated if a thermal model is given, else the kinematics of
    ``arm`` (the nominal arm, or the run's :class:`RunGeometry`: calibrated D-H table, base and
    head); always with its base pose and tool (the model was identified on them or checked
    against them when loaded)."""
    if model is None:
        return arm.fk(q_rad, "tcp")
    return compensated_T_cell_tcp(model, arm.T_cell_base, arm.T_tool0_tcp, q_rad, temps_c)


def inspect_hole(
    cell: CellConfig,
    arm: Arm | RunGeometry,
    model: ThermalModel | None,
    stereo: StereoCalibration,
    hole: HoleInCell,
    stop_index: int,
    left: np.ndarray,
    right: np.ndarray,
    q_rad: np.ndarray,
    temps_c: np.ndarray,
    sim_time_s: float,
    context: BudgetContext | None = None,
    located: LocatedStop | None = None,
    network_source: str = "",
    exclude: tuple[list, list] | None = None,
) -> tuple[HoleResult, HoleMeasurement | None]:
    """Measure ``hole`` from one pair and compare it with its nominal; never raises for a hole
    that is not there (``missing``) or cannot be measured (``unmeasured``: a resume retries
    it). ``context``: the run's budget inputs (default: the cell's, part temperature from the
    cell file or assumed, ISO 14253-1 rule). ``arm``: the kinematics the measurement is carried
    through (a :class:`RunGeometry` with a calibration adds its ``cell_calibration`` budget
    row). ``located``: the stop located against the surveyed markers (a referenced run): when
    it is referenced the hole is carried into the cell by the resected pose and its budget has
    the resection's and the survey's rows in place of the arm's (:mod:`cell.run.referenced`);
    either way ``extra["referencing"]`` says what happened. ``exclude``: per image, circles
    around the markers' labels, never taken for the hole (:func:`measure.measure_hole`)."""
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
            exclude=exclude,
        )
    except HoleNotFoundError as exc:
        return HoleResult(status="missing", reason=f"no hole found: {exc}", **base), None
    except MeasurementError as exc:
        return HoleResult(status="unmeasured", reason=f"not measurable: {exc}", **base), None
    t_meas = time.perf_counter() - t0
    ctx = context or budget_context(cell, stereo)
    T_head_left = invert(head_frame(stereo))
    referenced = located is not None and located.referenced
    T_cell_left = (located.resection.T_cell_left if referenced
                   else T_cell_tcp(arm, model, q_rad, temps_c) @ T_head_left)  # fmt: skip
    if located is not None and not referenced and located.T_cell_left_registered is not None:
        T_cell_left = located.T_cell_left_registered  # the arm, in the markers' frame
    T_part_left = T_part_cell @ T_cell_left
    T_nom = T_part_cell @ arm.fk(q_rad, "tcp") @ T_head_left
    center_nominal_fk = ctx.part.to_20c(T_nom[:3, :3] @ meas.center_m + T_nom[:3, 3])
    extra = {"center_part_uncompensated_m": [float(v) for v in center_nominal_fk]}
    if located is not None:
        extra["referencing"] = located.to_dict()
    normal_part = T_part_cell[:3, :3] @ hole.normal
    result = _measured(meas, T_part_left, hole, nominal, t_meas, extra, base, ctx, normal_part)
    center_tcp = T_head_left[:3, :3] @ meas.center_m + T_head_left[:3, 3]
    cal_A, cal_note = (None, "") if referenced else _calibration_factor(
        arm, q_rad, meas.center_m, T_part_cell[:3, :3])  # fmt: skip
    cal_cov = None if cal_A is None else cal_A @ cal_A.T
    contributions = hole_contributions(
        ctx, stereo, meas, T_part_left[:3, :3], T_part_cell[:3, :3], model, arm.T_cell_base,
        arm.T_tool0_tcp, q_rad, temps_c, center_tcp, np.array(result.center_part_m),
        result.diameter_m, cal_cov, cal_note)  # fmt: skip
    if referenced:
        rows = {c.name: c for c in contributions}
        inliers = np.asarray(meas.points_m, float)[np.asarray(meas.inliers, bool)]
        head = HeadInputs(stereo, ctx.calibration, inliers)
        contributions = referenced_contributions(
            located, meas.center_m, T_part_cell[:3, :3], rows["circle_fit"],
            rows["stereo_calibration"], rows["part_temperature"], network_source,
            head)  # fmt: skip
    delta = np.array(result.center_part_m) - nominal
    budget = combine(contributions, delta, normal_part, (ctx.part.note(),))
    extra = {**result.extra, **gdt_extra(contributions, T_part_left)}
    if cal_A is not None:  # the shared calibration error's factor, for the datum-frame draws
        extra["cell_calibration_factor_part"] = cal_A.tolist()
    net_F = None if located is None else survey_markers_factor(located, meas.center_m,
                                                                T_part_cell[:3, :3])  # fmt: skip
    if net_F is not None:  # the shared network error's factor, for the datum-frame draws
        extra["survey_markers_factor_part"] = net_F.tolist()
    result = replace(result, extra=extra)
    return _decided(result, budget, ctx.rule), meas


def uncaptured_hole(
    cell: CellConfig,
    hole: HoleInCell,
    stop_index: int,
    reason: str,
    q_rad: np.ndarray,
    temps_c: np.ndarray,
    sim_time_s: float,
) -> HoleResult:
    """The result of a stop where the head gave no pair of one trigger (``reason``, from
    :class:`cell.camera.errors.PairError`): ``unmeasured``, so a resume measures it again."""
    T_part_cell = invert(cell.T_cell_part())
    nominal = T_part_cell[:3, :3] @ hole.position_m + T_part_cell[:3, 3]
    base = _base_fields(hole, stop_index, nominal, q_rad, temps_c, sim_time_s)
    return HoleResult(status="unmeasured", reason=f"no stereo pair: {reason}", **base)


def _calibration_factor(
    arm: Arm | RunGeometry, q_rad: np.ndarray, center_left_m: np.ndarray, R_part_cell: np.ndarray
) -> tuple[np.ndarray | None, str]:
    """The cell calibration's error factor of the centre (3, p, part frame: error ``A z``,
    ``z ~ N(0, I)`` shared by the run) and its note; None without a calibration."""
    if not isinstance(arm, RunGeometry) or arm.run_calibration is None:
        return None, ""
    A = R_part_cell @ arm.point_factor_cell(q_rad, center_left_m)
    rc = arm.run_calibration
    note = (f"{rc.source} ({rc.calibration.created_utc}): hand-eye, D-H terms and plate pose, "
            "first order with their correlations, relative to the plate")  # fmt: skip
    return A, note


def _decided(result: HoleResult, budget, rule: str) -> HoleResult:
    """``result`` with its budget, expanded uncertainties and decision."""
    decision = None
    if result.tolerance_m is not None:
        decision = decide_hole([
            decide_one(result.position_deviation_m, budget.U_position_m, result.tolerance_m, rule),
            decide_one(result.diameter_deviation_m, budget.U_diameter_m, result.tolerance_m, rule),
        ])  # fmt: skip
    return replace(result, U_position_m=budget.U_position_m, U_diameter_m=budget.U_diameter_m,
                   decision=decision, decision_rule=rule, budget=budget.to_dict())  # fmt: skip


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
    ctx: BudgetContext,
    normal_part_m: np.ndarray,
) -> HoleResult:
    """The result of a measured hole: centre and axis carried into the part frame by
    ``T_part_left``, centre and diameter corrected to 20 degC, deviations and the verdict
    against the tolerance; ``suspect`` flags a measurement of doubtful quality whatever the
    verdict."""
    center_t = T_part_left[:3, :3] @ meas.center_m + T_part_left[:3, 3]
    center = ctx.part.to_20c(center_t)
    diameter = float(ctx.part.to_20c(meas.diameter_m))
    normal = T_part_left[:3, :3] @ meas.normal
    extra = {**extra, "center_part_at_temperature_m": [float(v) for v in center_t],
             "diameter_at_temperature_m": float(meas.diameter_m)}  # fmt: skip
    dpos, ddia, ok, axial = deviations(center, diameter, nominal_part_m, hole.diameter_m,
                                       hole.tolerance_m, normal_part_m)  # fmt: skip
    cov = np.asarray(meas.cov_center_radius, float)
    return HoleResult(
        status="suspect" if meas.status == "suspect" else ("ok" if ok else "fail"),
        passed=ok,
        center_part_m=tuple(float(v) for v in center),
        normal_part=tuple(float(v) for v in normal),
        diameter_m=diameter,
        position_deviation_m=dpos,
        axial_deviation_m=axial,
        diameter_deviation_m=ddia,
        u_center_m=float(np.sqrt(max(np.trace(cov[:3, :3]), 0.0))),
        u_diameter_m=float(2.0 * np.sqrt(max(cov[3, 3], 0.0))),
        rms_m=float(meas.rms_m),
        n_points=int(meas.n_points),
        measure_time_s=measure_time_s,
        extra=extra,
        **base,
    )
