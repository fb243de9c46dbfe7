"""The cell calibration: one least-squares adjustment of all views' reprojection errors.

Observations -> refusals (:mod:`cell.calibration.estimate.refusals`) -> starting values from OpenCV
(:mod:`cell.calibration.estimate.initial`) -> identifiability
(:mod:`cell.calibration.estimate.identifiability`)
-> ``scipy.optimize.least_squares`` (trust-region reflective, analytic Jacobian from
:mod:`cell.calibration.estimate.model`, columns scaled by their norms, plain squared loss so the
covariance means what it says) -> :class:`~cell.calibration.estimate.result.CellCalibration`.

Covariance of every free unknown (:mod:`cell.calibration.estimate.covariance`): the corner noise
``s^2`` from the residuals, taken equal in both cameras and independent between corners, plus
(by default) an independent error of each view's flange pose (the arm's repeatability and
what the kinematic model leaves out), estimated from the per-view residuals or given; with a
scatter, the fit is repeated by generalised least squares (each view's residuals whitened by
``Omega_v^-1/2``) and ``(J^T Omega^-1 J)^-1`` is stated. With ``flange_scatter=False``,
``s^2 (J^T J)^-1``. The intrinsics are taken as exact (from the stereo calibration file); the
target's geometry as exact (it fixes the scale).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field, replace

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import least_squares
from scipy.spatial.transform import Rotation

from cell.calibration.errors import CalibrationDataError, DegenerateCalibrationError
from cell.calibration.estimate.assemble import build_calibration
from cell.calibration.estimate.covariance import (
    ViewWhitening,
    flange_scatter_covariance,
    gls_covariance,
    white_covariance,
)
from cell.calibration.estimate.identifiability import IdentifiabilityReport, choose_free
from cell.calibration.estimate.initial import InitialEstimate, initial_estimate
from cell.calibration.estimate.model import (
    N_INTRINSIC,
    State,
    column_names,
    flange_poses,
    intrinsic_names,
    predict,
    step_state,
)
from cell.calibration.estimate.observations import CalibrationObservations
from cell.calibration.estimate.refusals import check_views
from cell.calibration.estimate.result import (
    CellCalibration,
    Provenance,
)
from robots.calibration import structural_redundancies, term_names
from robots.dh import DHTable
from robots.transforms import so3_left_jacobian

Array = NDArray[np.float64]


@dataclass(frozen=True)
class SolveOptions:
    """Settings of the adjustment.

    Attributes:
        estimate_kinematics: estimate the D-H error terms (when the views give joints and a
            nominal table is given).
        estimate_stereo: estimate the stereo extrinsics (stereo heads); else they are taken
            from the stereo calibration as exact.
        max_condition: largest condition number of the column-normalised Jacobian accepted.
        effect_floor_px: an unknown whose unit change (1 m, 1 rad) moves the corners by less
            (root sum of squares, px) has no effect.
        min_views: fewest views accepted (and fewest left images that see the target).
        min_rotation_rad: smallest relative rotation of a view pair that counts for the axis
            spread; the largest must reach it.
        min_axis_spread_rad: smallest spread of the relative rotation axes.
        max_nfev: limit of residual evaluations of the solver.
        flange_scatter: model an independent error of each view's flange pose in the
            covariance (:mod:`cell.calibration.estimate.covariance`); False: corner noise only.
        flange_sigma_m, flange_sigma_rad: that error per axis (m, rad), e.g. from the arm's
            repeatability; ``None``: estimated from the per-view residuals.
        max_dh_length_m, max_dh_angle_rad: largest plausible D-H length and angle error; a
            fit beyond says the joints belong to another arm (or another joint zero) than the
            nominal table, and is refused.
        estimate_intrinsics: estimate corrections of each camera's fx, fy, cx, cy (px) and
            k1, k2, p1, p2, k3 (OpenCV distortion) with the rest, as nuisance unknowns: the
            other estimates are then free of the stereo calibration's lens error and their
            covariance holds the lens' uncertainty (marginalised); the corrections are
            reported in the notes, not written as estimates (the run measures with stereo.json).
    """

    estimate_kinematics: bool = True
    estimate_stereo: bool = True
    max_condition: float = 1e4
    effect_floor_px: float = 1.0
    min_views: int = 3
    min_rotation_rad: float = math.radians(5.0)
    min_axis_spread_rad: float = math.radians(5.0)
    max_nfev: int = 200
    max_dh_length_m: float = 0.01
    max_dh_angle_rad: float = math.radians(2.0)
    flange_scatter: bool = True
    flange_sigma_m: float | None = None
    flange_sigma_rad: float | None = None
    estimate_intrinsics: bool = False

    def __post_init__(self) -> None:
        if not self.max_condition > 1.0:
            raise ValueError(f"max_condition must be > 1, got {self.max_condition}")
        if self.min_views < 3:
            raise ValueError(f"min_views must be at least 3, got {self.min_views}")


@dataclass(frozen=True, eq=False)
class CalibrationResult:
    """Outcome of :func:`solve_calibration`: ``status`` "calibrated", the estimates, the rank
    report, the OpenCV start (every method's hand-eye) and timings (s)."""

    status: str
    calibration: CellCalibration
    report: IdentifiabilityReport
    initial: InitialEstimate | None
    timings: dict[str, float] = field(default_factory=dict)
    intrinsics: dict[str, tuple[float, float]] = field(default_factory=dict)


class _Problem:
    """Residuals and Jacobian over the free columns, relative to a start state."""

    def __init__(
        self, obs: CalibrationObservations, dh: DHTable | None, start: State, free: tuple[str, ...]
    ) -> None:
        self.obs, self.dh, self.start, self.free = obs, dh, start, free
        stereo = start.T_left_right is not None
        kinematic = dh is not None and obs.has_joints
        self.columns = column_names(stereo, kinematic, start.intrinsics is not None)
        self.idx = [self.columns.index(c) for c in free]
        self._x: Array | None = None
        self._pred = None

    def _at(self, x: Array):
        if self._x is None or not np.array_equal(x, self._x):
            self._x, self._pred = (
                x.copy(),
                predict(self.obs, self.dh, step_state(self.start, x, self.free)),
            )
        return self._pred

    def residuals(self, x: Array) -> Array:
        return self._at(x).residuals

    def jacobian(self, x: Array) -> Array:
        J = self._at(x).jacobian[:, self.idx].copy()
        for prefix in ("T_tool0_camera", "T_base_target", "T_left_right"):
            names = [f"{prefix}.r{a}_rad" for a in "xyz"]
            if all(n in self.free for n in names):
                k = [self.free.index(n) for n in names]
                J[:, k] = J[:, k] @ so3_left_jacobian(self._x[k])
        return J


def _fixed_columns(
    obs: CalibrationObservations,
    dh: DHTable | None,
    columns: tuple[str, ...],
    options: SolveOptions,
) -> dict[str, str]:
    fixed: dict[str, str] = {}
    if dh is not None and obs.has_joints:
        if options.estimate_kinematics:
            fixed = {f"dh.{k}": v for k, v in structural_redundancies(dh).items()}
        else:
            fixed = {f"dh.{n}": "kinematic terms not estimated (options)" for n in term_names()}
    if not options.estimate_stereo:
        fixed.update(
            {
                c: "stereo extrinsics taken from the stereo calibration"
                for c in columns
                if c.startswith("T_left_right.")
            }
        )
    return fixed


def solve_calibration(
    obs: CalibrationObservations,
    dh: DHTable | None = None,
    options: SolveOptions | None = None,
    provenance: Provenance | None = None,
    start: State | None = None,
) -> CalibrationResult:
    """Estimate hand-eye, target pose, stereo extrinsics and D-H errors from ``obs``.

    ``dh``: the nominal table (required for views with joints; the D-H terms are estimated
    then). ``start``: starting values instead of OpenCV's (D-H errors start at ``start.delta``).
    Raises :class:`DegenerateCalibrationError` for a data set that cannot determine the
    hand-eye, :class:`CalibrationDataError` for unusable observations.
    """
    opts = options or SolveOptions()
    t0 = time.perf_counter()
    if obs.has_joints and dh is None:
        raise DegenerateCalibrationError("the views give joints but no nominal D-H table was given")
    T_bt = flange_poses(obs, dh, np.zeros(24))
    check_views(obs, T_bt, opts.min_views, opts.min_rotation_rad, opts.min_axis_spread_rad)
    init = None
    if start is None:
        init = initial_estimate(obs, T_bt)
        L = obs.cameras.T_left_right if obs.cameras.stereo else None
        start = State(init.best.T_tool0_camera, init.best.T_base_target, L, np.zeros(24))
    if start.T_left_right is not None and not obs.corners("right")[1].any():
        start = replace(start, T_left_right=None)  # no right image saw the plate: mono
    t_init = time.perf_counter()
    stereo = start.T_left_right is not None
    kinematic = dh is not None and obs.has_joints
    if opts.estimate_intrinsics and start.intrinsics is None:
        start = replace(start, intrinsics=np.zeros(N_INTRINSIC * (2 if stereo else 1)))
    columns = column_names(stereo, kinematic, start.intrinsics is not None)
    # a first fit of the poses alone puts the rank test at a good linearisation point
    poses = tuple(c for c in columns if not c.startswith("dh."))
    if not opts.estimate_stereo:
        poses = tuple(c for c in poses if not c.startswith("T_left_right."))
    start = _fit(obs, dh, start, poses, opts)
    J = predict(obs, dh, start).jacobian
    report = choose_free(
        J, columns, _fixed_columns(obs, dh, columns, opts), opts.max_condition, opts.effect_floor_px
    )
    t_rank = time.perf_counter()
    state = _fit(obs, dh, start, report.free, opts)
    _check_plausible(obs, state, report.free, opts)
    pred = predict(obs, dh, state, flange_jac=True)  # at the solution: the perturbation is exact
    Jf = pred.jacobian[:, [columns.index(c) for c in report.free]]
    n, p = len(pred.residuals), len(report.free)
    if n <= p:
        raise DegenerateCalibrationError(f"{n} corner coordinates for {p} unknowns")
    if opts.flange_scatter:
        n_stereo = sum(c.startswith(("T_left_right.", "intrinsics.")) for c in report.free)
        rows_view = np.repeat(pred.view_index, 2)
        cr = flange_scatter_covariance(
            Jf,
            pred.residuals,
            pred.flange_jacobian,
            rows_view,
            n_stereo,
            opts.flange_sigma_m,
            opts.flange_sigma_rad,
        )
        if cr.flange_sigma_m > 0 or cr.flange_sigma_rad > 0:
            # the views' corners move together: weight by Omega^-1 (generalised least squares)
            weight = ViewWhitening(
                pred.flange_jacobian, rows_view, cr.s2_px, cr.flange_sigma_m, cr.flange_sigma_rad
            )
            state = _fit(obs, dh, state, report.free, opts, weight)
            _check_plausible(obs, state, report.free, opts)
            pred = predict(obs, dh, state)
            Jf = pred.jacobian[:, [columns.index(c) for c in report.free]]
            cr = gls_covariance(weight(Jf), cr)
    else:
        cr = white_covariance(Jf, pred.residuals)
    t_end = time.perf_counter()
    report, cr, intrinsics = _marginal_intrinsics(report, cr, state)
    cal = build_calibration(obs, dh, state, report, cr, pred, provenance or Provenance(), init)
    if intrinsics:
        shown = ", ".join(f"{n[len('intrinsics.') :]} {v:+.3g}±{s:.2g}"
                          for n, (v, s) in intrinsics.items())  # fmt: skip
        cal = replace(
            cal,
            notes=(
                *cal.notes,
                f"intrinsics corrected (marginalised; fx..cy px, k, p: distortion): {shown}",
            ),
        )
    return CalibrationResult(
        status="calibrated",
        calibration=cal,
        report=report,
        initial=init,
        intrinsics=intrinsics,
        timings={
            "initial_s": t_init - t0,
            "rank_s": t_rank - t_init,
            "solve_s": t_end - t_rank,
            "total_s": t_end - t0,
        },
    )


def _marginal_intrinsics(report: IdentifiabilityReport, cr, state: State):
    """The report and covariance without the intrinsic corrections (their marginal: the
    sub-block of the others), and the corrections' values and sigmas (px) by name."""
    names = [c for c in report.free if c.startswith("intrinsics.")]
    if not names:
        return report, cr, {}
    keep = [i for i, c in enumerate(report.free) if not c.startswith("intrinsics.")]
    cov = cr.covariance
    stereo = len(state.intrinsics) == 2 * N_INTRINSIC
    values = dict(zip(intrinsic_names(stereo), state.intrinsics, strict=True))
    out = {n: (float(values[n]), float(np.sqrt(cov[report.free.index(n)] [report.free.index(n)])))
           for n in names}  # fmt: skip
    report = replace(report, free=tuple(report.free[i] for i in keep))
    return report, replace(cr, covariance=cov[np.ix_(keep, keep)]), out


def _check_plausible(
    obs: CalibrationObservations, state: State, free: tuple[str, ...], opts: SolveOptions
) -> None:
    """Refuse D-H errors no arm of the nominal model has (another arm's joints, say)."""
    for k, name in enumerate(term_names()):
        if f"dh.{name}" not in free:
            continue
        value = float(state.delta[k])
        length = name.endswith("_m")
        limit = opts.max_dh_length_m if length else opts.max_dh_angle_rad
        if abs(value) > limit:
            shown = f"{value * 1e3:.2f} mm" if length else f"{math.degrees(value):.3f} deg"
            bound = f"{limit * 1e3:g} mm" if length else f"{math.degrees(limit):g} deg"
            raise CalibrationDataError(
                obs.source,
                f"the fit needs a D-H error {name} = {shown} (plausible: within {bound}): "
                "do the joints come from the arm of the nominal table (the cell's robot model)?",
            )


def _fit(
    obs: CalibrationObservations,
    dh: DHTable | None,
    start: State,
    free: tuple[str, ...],
    opts: SolveOptions,
    weight: ViewWhitening | None = None,
) -> State:
    """Least squares over the free unknowns from ``start``; ``weight`` whitens the residuals
    (generalised least squares with the views' flange scatter)."""
    prob = _Problem(obs, dh, start, free)
    fun, jac = prob.residuals, prob.jacobian
    if weight is not None:
        fun, jac = (lambda x: weight(prob.residuals(x))), (lambda x: weight(prob.jacobian(x)))
    sol = least_squares(
        fun,
        np.zeros(len(free)),
        jac=jac,
        method="lm",
        x_scale="jac",
        xtol=1e-12,
        ftol=1e-12,
        gtol=1e-10,
        max_nfev=opts.max_nfev,
    )
    return step_state(start, sol.x, free)


def pose_error(T_est: Array, T_true: Array) -> tuple[float, float]:
    """``(position error (m), rotation angle (rad))`` between two poses."""
    dp = float(np.linalg.norm(T_est[:3, 3] - T_true[:3, 3]))
    da = float(Rotation.from_matrix(T_est[:3, :3] @ T_true[:3, :3].T).magnitude())
    return dp, da


__all__ = ["CalibrationResult", "SolveOptions", "pose_error", "solve_calibration"]
