"""What a run knows for every hole's budget (:class:`BudgetContext`) and the contributions of
one measured hole (:func:`hole_contributions`).

Frames: the measurement in the LEFT camera frame, rotated into the part frame by
``R_part_left``; the thermal model's covariance in the cell frame, rotated by ``R_part_cell``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from cell.uncertainty.budget import Contribution
from cell.uncertainty.calibration import default_uncertainty, jacobian_covariance
from cell.uncertainty.decision import DEFAULT_RULE
from cell.uncertainty.part_temperature import PartThermalState, part_state
from cell.uncertainty.repeatability import repeatability_rp_m, sigma_per_axis_m
from cell.uncertainty.thermal import thermal_note, thermal_point_covariance
from measure import StereoCalibration
from measure.calibration_uncertainty import CalibrationUncertainty
from robots.thermal.model import ThermalModel


@dataclass(frozen=True)
class BudgetContext:
    """The run-wide inputs of the budget.

    Attributes:
        calibration: the stereo calibration's uncertainties (the file's, or the defaults).
        calibration_note: where they came from.
        part: the part's temperature state and material.
        rp_m: the arm's ISO 9283 pose repeatability (m); ``rp_note`` where it came from.
        rule: the decision rule (``iso14253`` or ``simple``).
    """

    calibration: CalibrationUncertainty
    calibration_note: str
    part: PartThermalState
    rp_m: float
    rp_note: str
    rule: str = DEFAULT_RULE


def budget_context(
    cell,
    stereo: StereoCalibration,
    part: PartThermalState | None = None,
    rule: str = DEFAULT_RULE,
) -> BudgetContext:
    """The context of a run of ``cell`` (:class:`cell.config.CellConfig`) with head ``stereo``."""
    if stereo.uncertainty is not None:
        unc, note = stereo.uncertainty, f"uncertainty block of {stereo.source}"
    else:
        unc = default_uncertainty(stereo)
        note = (f"{stereo.source} states no uncertainty: default figures of a careful "
                "calibration (cell.uncertainty.calibration)")  # fmt: skip
    rp, rp_note = repeatability_rp_m(cell.robot.model, cell.robot.repeatability_m)
    return BudgetContext(unc, note, part or part_state(cell), rp, rp_note, rule)


def hole_contributions(
    ctx: BudgetContext,
    stereo: StereoCalibration,
    meas,
    R_part_left: np.ndarray,
    R_part_cell: np.ndarray,
    model: ThermalModel | None,
    T_cell_base: np.ndarray,
    T_tool0_tcp: np.ndarray,
    q_rad: np.ndarray,
    temps_c: np.ndarray,
    center_tcp_m: np.ndarray,
    center_part_20_m: np.ndarray,
    diameter_20_m: float,
    cell_calibration_cov_m2: np.ndarray | None = None,
    cell_calibration_note: str = "",
) -> list[Contribution]:
    """The contributions of one measured hole (see :mod:`cell.uncertainty.budget`): five, and
    ``cell_calibration`` when the run applies a cell calibration (``cell_calibration_cov_m2``:
    the centre's covariance in the part frame, m^2, from the calibration's covariance:
    :meth:`cell.calibration.use.run_calibration.RunGeometry.point_covariance_cell` rotated into the
    part)."""
    cov = np.asarray(meas.cov_center_radius, float)
    fit = Contribution("circle_fit", R_part_left @ cov[:3, :3] @ R_part_left.T, 4.0 * cov[3, 3],
                       f"covariance of the circle fit ({int(meas.n_points)} points)")  # fmt: skip
    points = np.asarray(meas.points_m, float)[np.asarray(meas.inliers, bool)]
    cal = jacobian_covariance(stereo, points, ctx.calibration)
    calib = Contribution("stereo_calibration", R_part_left @ cal[:3, :3] @ R_part_left.T,
                         4.0 * cal[3, 3], ctx.calibration_note)  # fmt: skip
    th = thermal_point_covariance(model, T_cell_base, T_tool0_tcp, q_rad, temps_c, center_tcp_m)
    th_note = thermal_note(model)
    thermal = Contribution("thermal_model", R_part_cell @ th @ R_part_cell.T, 0.0, th_note)
    s = sigma_per_axis_m(ctx.rp_m)
    rep = Contribution(
        "robot_repeatability",
        s * s * np.eye(3),
        0.0,
        f"RP {ctx.rp_m * 1e3:.3f} mm ({ctx.rp_note}) = {s * 1e6:.1f} um per axis",
    )
    rel = ctx.part.relative_u()
    c20 = np.asarray(center_part_20_m, float)
    temp = Contribution("part_temperature", rel * rel * np.outer(c20, c20),
                        (rel * diameter_20_m) ** 2, ctx.part.note())  # fmt: skip
    out = [fit, calib, thermal, rep, temp]
    if cell_calibration_cov_m2 is not None:
        out.append(Contribution("cell_calibration", np.asarray(cell_calibration_cov_m2, float),
                                0.0, cell_calibration_note))  # fmt: skip
    return out
