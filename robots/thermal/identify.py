"""Identification of the thermal model from reference-target observations.

Each (target, pose) group is measured many times while the arm warms. The
unknown cold position of every group (which also absorbs static errors of the
target positions, the base pose and the nominal geometry) is removed by taking
each group's deviations from its mean; the thermal terms are then fitted to
those deviations by Levenberg-Marquardt (``scipy.optimize.least_squares``,
``method="lm"``). Before fitting, the Jacobian of the deviations with respect to
every candidate term is examined: terms without an effect, and terms that the
data cannot separate from others (smallest singular value of the
column-normalised Jacobian too small), are refused with a reason.

Uncertainty: ``sigma^2 (J^T J)^-1`` with ``sigma`` from the residual, multiplied by the AR(1)
variance factor ``(1 + rho) / (1 - rho)`` when the residuals of each pose group are serially
correlated in time (lag-1 correlation ``rho`` above the white-noise level ``2 / sqrt(pairs)``):
then the model's structure misses something (a link lagging its sensor, say), the rows are not
independent measurements, and the plain covariance would be too optimistic.

The noise of one sensor reading (``fit["reading_noise_K"]``, :func:`reading_noise_K`) is kept
too: a prediction at a stop rests on that stop's readings and on the cold reference readings,
whose noise the terms' covariance does not contain
(:func:`robots.thermal.uncertainty.reading_covariance`).

Units: terms ``k_link*`` in 1/K, ``c_joint*`` in rad/K; internally scaled by
1e-6 (ppm/K, urad/K) so the solver works on numbers near one.
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import least_squares

from robots.dh import DHTable
from robots.thermal.errors import ThermalDataError, ThermalSpecError, UnidentifiableError
from robots.thermal.model import (
    TERM_SCALE,
    ThermalModel,
    ThermalSpec,
    coefficient_vectors,
    drifted_arrays,
    fk_rows,
    term_kind_and_link,
)
from robots.thermal.observations import CellGeometry, Observations, predict_p_tcp

Array = NDArray[np.float64]
log = logging.getLogger(__name__)


@dataclass(frozen=True)
class IdentifyOptions:
    """Settings of the identification.

    Attributes:
        max_condition: largest condition number of the column-normalised Jacobian accepted;
            beyond it the least separable term is refused (repeatedly).
        effect_floor_m: a term whose unit step (1 ppm/K or 1 urad/K) changes the deviations
            by less than this (m, root of the sum of squares) has no effect and is refused.
        max_nfev: limit of residual evaluations of the solver.
    """

    max_condition: float = 1e3
    effect_floor_m: float = 1e-9
    max_nfev: int = 200

    def __post_init__(self) -> None:
        if not self.max_condition > 1.0:
            raise ThermalSpecError("max_condition", self.max_condition, "must be greater than 1")
        if not self.effect_floor_m >= 0.0:
            raise ThermalSpecError("effect_floor_m", self.effect_floor_m, "must be >= 0")
        if self.max_nfev < 1:
            raise ThermalSpecError("max_nfev", self.max_nfev, "must be at least 1")


@dataclass(frozen=True)
class IdentifiabilityReport:
    """Rank and condition of the identification problem.

    Attributes:
        candidates: every term considered.
        kept: terms estimated.
        refused: term -> reason, for every term not estimated.
        singular_values: of the column-normalised Jacobian of all terms with an effect (descending).
        rank: number of those singular values above ``s_max / max_condition``.
        condition_all: condition number of all terms with an effect (inf when singular).
        condition_kept: condition number of the kept terms.
    """

    candidates: tuple[str, ...]
    kept: tuple[str, ...]
    refused: dict[str, str]
    singular_values: tuple[float, ...]
    rank: int
    condition_all: float
    condition_kept: float


@dataclass(frozen=True)
class IdentificationResult:
    """Outcome of :func:`identify`: ``status`` is "identified" (every candidate) or "partial"."""

    status: str
    model: ThermalModel
    report: IdentifiabilityReport
    residual_rms_m: float
    residual_rms_before_m: float
    sigma_m: float
    n_rows: int
    n_groups: int
    dof: int
    timings: dict[str, float] = field(default_factory=dict)


def reference_from_cold(obs: Observations) -> tuple[float, ...]:
    """Per-sensor mean reading (degC) of the earliest observation time: the cold state."""
    cold = obs.time_s == np.min(obs.time_s)
    return tuple(float(v) for v in obs.temps_degC[cold].mean(axis=0))


class _Problem:
    """Group-demeaned deviations of the observations and of the model's predictions."""

    def __init__(
        self, obs: Observations, geometry: CellGeometry, table: DHTable, spec: ThermalSpec
    ):
        self.table = table
        self.geometry = geometry
        self.q = obs.q_rad
        self.groups = obs.groups()
        self.n_groups = int(self.groups.max()) + 1 if len(obs) else 0
        self.counts = np.bincount(self.groups, minlength=self.n_groups).astype(float)
        self.dT = spec.link_delta_K(obs.temps_degC)
        self.p_base = geometry.targets_base_m(obs.target_ids)
        self.meas = self.demean(obs.p_tcp_m)

    def demean(self, p: Array) -> Array:
        """Subtract each group's mean (N, 3)."""
        sums = np.zeros((self.n_groups, 3))
        np.add.at(sums, self.groups, p)
        return p - (sums / self.counts[:, None])[self.groups]

    def predicted(self, terms: tuple[str, ...], x: Array) -> Array:
        """Demeaned predicted positions (N, 3) for scaled term values ``x``."""
        values = {
            n: float(v) * TERM_SCALE[term_kind_and_link(n)[0]]
            for n, v in zip(terms, x, strict=True)
        }
        k, c = coefficient_vectors(values)
        a, d, alpha, theta = drifted_arrays(self.table, k, c, self.dT)
        T = fk_rows(a, d, alpha, theta, self.table.joint_values(self.q))
        return self.demean(predict_p_tcp(T, self.geometry.T_tool0_tcp, self.p_base))

    def residual(self, terms: tuple[str, ...], x: Array) -> Array:
        return (self.predicted(terms, x) - self.meas).ravel()

    def jacobian(self, terms: tuple[str, ...], x: Array, step: float = 1.0) -> Array:
        """Central-difference Jacobian (m per scaled unit), shape (3N, len(terms))."""
        cols = []
        for j in range(len(terms)):
            e = np.zeros(len(terms))
            e[j] = step
            cols.append(
                (self.predicted(terms, x + e) - self.predicted(terms, x - e)).ravel() / (2 * step)
            )
        return np.column_stack(cols) if cols else np.zeros((3 * len(self.q), 0))


def serial_correlation(
    residual: Array, groups: NDArray[np.int64], time_s: Array
) -> tuple[float, int]:
    """Pooled lag-1 correlation of the fit residuals (N, 3) within each pose group in time
    order, and the number of consecutive pairs it rests on (per axis)."""
    num = den = 0.0
    pairs = 0
    for g in np.unique(groups):
        idx = np.flatnonzero(groups == g)
        r = residual[idx[np.argsort(time_s[idx], kind="stable")]]
        num += float(np.sum(r[1:] * r[:-1]))
        den += float(np.sum(r**2))
        pairs += 3 * (len(idx) - 1)
    return (num / den if den > 0 else 0.0), pairs


def reading_noise_K(time_s: Array, temps_degC: Array, degree: int = 4) -> float:
    """Standard deviation (K) of one sensor reading, pooled over the sensors: the residual of a
    smooth warm-up curve (polynomial of ``degree`` in time, per sensor) through the readings of
    every observation; 0.0 with too few observations (fewer than ``3 * (degree + 1)``) or no
    spread in time. A first-order warm-up over the reference rounds leaves a quartic within a
    few mK, so the figure is the readings' noise (slightly high if the curve is not smooth)."""
    t = np.asarray(time_s, float)
    temps = np.asarray(temps_degC, float).reshape(len(t), -1)
    n = len(t)
    if n < 3 * (degree + 1) or np.ptp(t) <= 0.0:
        return 0.0
    V = np.vander((t - t.mean()) / np.ptp(t), degree + 1)
    coef, *_ = np.linalg.lstsq(V, temps, rcond=None)
    r = temps - V @ coef
    return float(np.sqrt(np.sum(r**2) / (temps.shape[1] * (n - degree - 1))))


def inflation_factor(rho: float, pairs: int) -> float:
    """The covariance factor for serially correlated residuals: ``(1 + rho) / (1 - rho)`` (the
    AR(1) variance factor; ``rho`` capped at 0.95) when ``rho`` exceeds ``2 / sqrt(pairs)``
    (white noise stays below it 97.5 % of the time), else 1."""
    if pairs < 1 or rho <= 2.0 / np.sqrt(pairs):
        return 1.0
    rho = min(rho, 0.95)
    return (1.0 + rho) / (1.0 - rho)


def _no_effect_reason(name: str, table: DHTable, spec: ThermalSpec, problem: _Problem) -> str:
    kind, link = term_kind_and_link(name)
    a, d, _, _ = table.arrays()
    if kind == "k" and a[link] == 0.0 and d[link] == 0.0:
        return f"link {link + 1} has no D-H length (a{link + 1} = d{link + 1} = 0)"
    sensor = spec.sensor_names[spec.sensor_of_link[link]]
    if np.ptp(problem.dT[:, link]) == 0.0:
        return f"the temperature of sensor {sensor!r} never changes in the observations"
    return "no measurable effect on the target deviations with this pose plan"


def _normalised_svd(J: Array) -> tuple[Array, Array]:
    norms = np.linalg.norm(J, axis=0)
    _, s, Vt = np.linalg.svd(J / norms, full_matrices=False)
    return s, Vt


def _condition(s: Array) -> float:
    return float(s[0] / s[-1]) if len(s) and s[-1] > 0 else float("inf")


def identifiability(
    problem: _Problem, spec: ThermalSpec, options: IdentifyOptions
) -> IdentifiabilityReport:
    """Refuse terms without effect, then the least separable ones until the condition is met."""
    candidates = spec.candidate_terms()
    J = problem.jacobian(candidates, np.zeros(len(candidates)))
    norms = np.linalg.norm(J, axis=0)
    refused: dict[str, str] = {}
    kept = []
    for j, name in enumerate(candidates):
        if norms[j] < options.effect_floor_m:
            refused[name] = _no_effect_reason(name, problem.table, spec, problem)
        else:
            kept.append(j)
    s_all = _normalised_svd(J[:, kept])[0] if kept else np.zeros(0)
    rank = int(np.sum(s_all > s_all[0] / options.max_condition)) if len(s_all) else 0
    while kept:
        s, Vt = _normalised_svd(J[:, kept])
        if _condition(s) <= options.max_condition:
            break
        v = Vt[-1]
        # among the terms in the least determined combination, drop the one with the smallest
        # effect: the others keep its share as an effective coefficient
        involved = np.flatnonzero(np.abs(v) >= 0.5 * np.max(np.abs(v)))
        worst = int(involved[np.argmin(norms[np.asarray(kept)[involved]])])
        partners = [
            f"{v[i]:+.2f}*{candidates[kept[i]]}" for i in np.argsort(-np.abs(v)) if abs(v[i]) > 0.1
        ]
        refused[candidates[kept[worst]]] = (
            "not separable from the other terms with this pose plan and these temperatures, "
            "its share goes to the kept terms "
            f"(condition {_condition(s):.3g} > {options.max_condition:.3g}; "
            f"least determined combination {' '.join(partners)})"
        )
        kept.pop(worst)
    s_kept = _normalised_svd(J[:, kept])[0] if kept else np.zeros(0)
    return IdentifiabilityReport(
        candidates=candidates,
        kept=tuple(candidates[j] for j in kept),
        refused=refused,
        singular_values=tuple(float(v) for v in s_all),
        rank=rank,
        condition_all=_condition(s_all),
        condition_kept=_condition(s_kept),
    )


def _check_inputs(obs: Observations, geometry: CellGeometry, spec: ThermalSpec) -> None:
    if tuple(obs.sensor_names) != tuple(spec.sensor_names):
        raise ThermalDataError(
            obs.source,
            f"the observations hold sensors {list(obs.sensor_names)}, "
            f"the model expects {list(spec.sensor_names)}",
        )
    if len(obs) == 0:
        raise ThermalDataError(obs.source, "no observations")
    obs.check_targets(geometry)


def identify(
    obs: Observations,
    geometry: CellGeometry,
    table: DHTable,
    spec: ThermalSpec,
    options: IdentifyOptions | None = None,
    robot_model: str = "",
) -> IdentificationResult:
    """Identify the terms of ``spec`` from observations; refuse what the data cannot determine.

    Raises :class:`UnidentifiableError` when no term can be determined or there are
    too few observations for the kept terms.
    """
    options = options or IdentifyOptions()
    t0 = time.perf_counter()
    _check_inputs(obs, geometry, spec)
    problem = _Problem(obs, geometry, table, spec)
    report = identifiability(problem, spec, options)
    if not report.kept:
        raise UnidentifiableError("no term has an effect on the observations", report.refused)
    terms = report.kept
    dof = 3 * len(obs) - 3 * problem.n_groups - len(terms)
    if dof < 1:
        raise UnidentifiableError(
            f"{len(obs)} rows in {problem.n_groups} pose groups leave {dof} degrees of freedom "
            f"for {len(terms)} terms; measure each pose at more temperatures"
        )
    x0 = np.zeros(len(terms))
    sol = least_squares(
        lambda x: problem.residual(terms, x),
        x0,
        jac=lambda x: problem.jacobian(terms, x),
        method="lm",
        max_nfev=options.max_nfev,
    )
    r = sol.fun
    sigma = float(np.sqrt(r @ r / dof))
    J = problem.jacobian(terms, sol.x)
    rho, pairs = serial_correlation(r.reshape(-1, 3), problem.groups, obs.time_s)
    inflation = inflation_factor(rho, pairs)
    cov = inflation * sigma**2 * np.linalg.pinv(J.T @ J)
    scale = np.array([TERM_SCALE[term_kind_and_link(n)[0]] for n in terms])
    values = {n: float(v) for n, v in zip(terms, sol.x * scale, strict=True)}
    std = {n: float(v) for n, v in zip(terms, np.sqrt(np.diag(cov)) * scale, strict=True)}
    r0 = problem.residual(terms, x0)
    rms = float(np.sqrt(np.mean(r**2)))
    model = ThermalModel(
        table=table,
        spec=spec,
        coefficients=values,
        std=std,
        refused=dict(report.refused),
        robot_model=robot_model,
        T_cell_base=np.asarray(geometry.T_cell_base, float),
        T_tool0_tcp=np.asarray(geometry.T_tool0_tcp, float),
        covariance=np.asarray(cov * np.outer(scale, scale), dtype=np.float64),
        fit={
            "residual_rms_m": rms,
            "residual_rms_before_m": float(np.sqrt(np.mean(r0**2))),
            "sigma_m": sigma,
            "residual_lag1_correlation": rho,
            "reading_noise_K": reading_noise_K(obs.time_s, obs.temps_degC),
            "covariance_inflation": inflation,
            "rank": float(report.rank),
            "condition": report.condition_kept,
            "n_rows": float(len(obs)),
            "n_groups": float(problem.n_groups),
        },
    )
    elapsed = time.perf_counter() - t0
    log.info("thermal identification: %d terms, rms %.2e m, %.3f s", len(terms), rms, elapsed)
    return IdentificationResult(
        status="identified" if not report.refused else "partial",
        model=model,
        report=report,
        residual_rms_m=rms,
        residual_rms_before_m=model.fit["residual_rms_before_m"],
        sigma_m=sigma,
        n_rows=len(obs),
        n_groups=problem.n_groups,
        dof=dof,
        timings={"identify_s": elapsed, "solver_nfev": float(sol.nfev)},
    )


def plan_report(
    obs: Observations,
    geometry: CellGeometry,
    table: DHTable,
    spec: ThermalSpec,
    options: IdentifyOptions | None = None,
) -> IdentifiabilityReport:
    """The rank/condition report of a pose plan without fitting (e.g. on simulated observations)."""
    _check_inputs(obs, geometry, spec)
    return identifiability(_Problem(obs, geometry, table, spec), spec, options or IdentifyOptions())
