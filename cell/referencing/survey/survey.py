"""The survey: views of the reference markers -> refusals -> one bundle adjustment (GTSAM) ->
outliers named and dropped -> the gauge -> :class:`SurveyResult`.

Outliers: an observation whose residual exceeds :data:`OUTLIER_SIGMA` times the pixel σ is
named and dropped, with a warning, and the adjustment is run again; when the rest no longer
passes the refusals the survey is refused naming it. Scale: from the scale bars when the cell
has any, else from the head's baseline alone (about 100 ppm, said in a warning).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, replace

import numpy as np

from cell.config import CellConfig
from cell.config.markers import marker_in_cell
from cell.referencing.errors import SurveyRefusedError
from cell.referencing.observations import MarkerView
from cell.referencing.sigma import SIGMA_FLOOR_PX, effective_sigma_px
from cell.referencing.survey.gauge import to_gauge
from cell.referencing.survey.problem import Array, Head, SurveyProblem, build_problem, predict
from cell.referencing.survey.refusals import check_network, usable_views
from cell.referencing.survey.result import SurveyResult
from cell.referencing.survey.solution import RawSolution
from cell.referencing.survey.solve_gtsam import solve_gtsam
from cell.uncertainty.calibration import default_uncertainty
from measure import StereoCalibration
from measure.calibration_uncertainty import CalibrationUncertainty
from robots.transforms import skew

#: an observation this many σ off is an outlier
OUTLIER_SIGMA = 5.0
#: the scale uncertainty of a network scaled by the head's baseline alone (ppm): the baseline's
#: calibration is good to about 0.01 mm in 100 mm
BASELINE_SCALE_PPM = 100.0


@dataclass(frozen=True)
class SurveyOptions:
    """``sigma_px``: the marker centres' stated standard deviation (px), from the marker
    benchmark (docs/referencing.md): the first adjustments' weights and the outlier limit;
    ``sigma_floor_px``: the smallest centre noise the final adjustment weighs with and states
    its covariance at (:mod:`cell.referencing.sigma`: a real head's floor by default);
    ``max_outlier_rounds``: re-adjustments after dropping outliers."""

    sigma_px: float = 0.05
    max_outlier_rounds: int = 3
    sigma_floor_px: float = SIGMA_FLOOR_PX


def survey(
    cell: CellConfig,
    stereo: StereoCalibration,
    views: list[MarkerView],
    options: SurveyOptions | None = None,
) -> SurveyResult:
    """Adjust ``views`` of ``cell``'s reference markers (module doc). Raises
    :class:`SurveyRefusedError` naming the marker, view or pieces."""
    o = options or SurveyOptions()
    t0 = time.perf_counter()
    if not cell.reference_markers:
        raise SurveyRefusedError(f"cell {cell.name!r}", "has no reference_markers")
    T_cell_part = cell.T_cell_part()
    ids = [m.id for m in cell.reference_markers]
    nominal = np.array([marker_in_cell(m, T_cell_part)[0] for m in cell.reference_markers])
    fixture = np.array([m.on == "fixture" for m in cell.reference_markers])
    kept, dropped = usable_views(views, ids, nominal)
    check_network(kept, ids, nominal)
    bars = [(b.from_, b.to, b.length_m, b.U_m) for b in cell.scale_bars]
    problem = build_problem(kept, stereo, ids, nominal, bars, o.sigma_px)
    warnings: list[str] = []
    outliers: list[tuple[str, str, str, float]] = []
    for round_ in range(o.max_outlier_rounds + 1):
        # the first round robust: a gross error drags the self-calibrated head in plain least
        # squares (a misread marker 36 px off bent the principal point by 150 px and left 93 %
        # of the observations over 5 sigma); the outliers are judged on that solution
        raw = solve_gtsam(problem, covariance=False, robust=round_ == 0)
        z = _normalised(problem, raw)
        bad = z > OUTLIER_SIGMA
        if not bad.any():
            break
        for k in np.flatnonzero(bad):
            item = (
                problem.view_ids[problem.view[k]],
                ids[problem.marker[k]],
                ("left", "right")[problem.side[k]],
                float(z[k]),
            )
            outliers.append(item)
            warnings.append(
                f"view {item[0]}: marker {item[1]} ({item[2]} image) is {item[3]:.1f} "
                f"sigma off: dropped"
            )
        problem = problem.without(~bad)
        _check_still(problem, kept, ids, nominal)
    # variance component: the image observations weighed at their own a posteriori noise (not
    # below the floor) in the final adjustment; the bars and the head's priors keep theirs
    vf = float(np.sum(_normalised(problem, raw) ** 2) * 2.0 / raw.dof)
    sigma_w = effective_sigma_px(o.sigma_px, vf, o.sigma_floor_px)
    t1 = time.perf_counter()
    raw = solve_gtsam(replace(problem, sigma_px=sigma_w), covariance=True)
    t2 = time.perf_counter()
    g = to_gauge(raw.points, raw.covariance, nominal, fixture)
    assert g.covariance is not None
    scale_ppm, source = _scale(problem, g.points, g.covariance)
    if not problem.bars:
        warnings.append(
            f"no scale bars: the scale comes from the head's baseline alone, about "
            f"{BASELINE_SCALE_PPM:.0f} ppm"
        )
    res = (predict(problem, raw.poses, raw.points, raw.head) - problem.uv).ravel()
    return SurveyResult(
        marker_ids=tuple(ids),
        positions_cell=g.points,
        covariance=g.covariance,
        gauge=g.kind,
        gauge_residuals_m=g.residuals_m,
        rms_px=float(np.sqrt(np.mean(res**2))),
        variance_factor=vf,
        sigma_px=o.sigma_px,
        sigma_effective_px=sigma_w * float(np.sqrt(max(raw.variance_factor, 1.0))),
        sigma_floor_px=o.sigma_floor_px,
        n_views=problem.n_views,
        n_observations=len(problem.uv),
        scale_sigma_ppm=scale_ppm,
        scale_source=source,
        dropped_views=tuple(dropped),
        outliers=tuple(outliers),
        warnings=tuple(warnings),
        timings={"adjust_s": t1 - t0, "covariance_s": t2 - t1},
        stereo=refined_head(stereo, raw.head, raw.head_covariance, float(np.sqrt(np.mean(res**2)))),
    )


def _normalised(problem: SurveyProblem, raw: RawSolution) -> Array:
    r = (predict(problem, raw.poses, raw.points, raw.head) - problem.uv) / problem.sigma_px
    return np.linalg.norm(r, axis=1) / np.sqrt(2.0)


def _check_still(
    problem: SurveyProblem, views: list[MarkerView], ids: list[str], nominal: Array
) -> None:
    """The refusals again on what is left after dropping outliers."""
    left = {
        (problem.view_ids[v], ids[j], s)
        for v, j, s in zip(problem.view, problem.marker, problem.side, strict=True)
    }
    rebuilt = []
    for view in views:
        uvl = {m: uv for m, uv in view.uv_left.items() if (view.view_id, m, 0) in left}
        uvr = {m: uv for m, uv in view.uv_right.items() if (view.view_id, m, 1) in left}
        rebuilt.append(MarkerView(view.view_id, uvl, uvr, view.T_cell_left_prior))
    check_network(rebuilt, ids, nominal)


def _scale(problem: SurveyProblem, points: Array, cov: Array) -> tuple[float, str]:
    """The scale's standard uncertainty (ppm) along the network's longest distance, and its
    source."""
    d = points[:, None, :] - points[None, :, :]
    i, j = np.unravel_index(np.argmax(np.einsum("ijk,ijk->ij", d, d)), d.shape[:2])
    u = (points[j] - points[i]) / np.linalg.norm(points[j] - points[i])
    a = np.zeros(len(cov))
    a[3 * i : 3 * i + 3], a[3 * j : 3 * j + 3] = -u, u
    ppm = 1e6 * float(np.sqrt(a @ cov @ a)) / float(np.linalg.norm(points[j] - points[i]))
    if problem.bars:
        return ppm, f"{len(problem.bars)} scale bars and the head's baseline"
    return max(ppm, BASELINE_SCALE_PPM), "the head's baseline alone"


def head_uncertainty(
    stereo: StereoCalibration, head: Head, covariance: tuple[Array, Array, Array], rms_px: float
) -> CalibrationUncertainty:
    """The self-calibrated head's one-sigma uncertainties from the adjustment's marginals: the
    camera matrices' and lens terms' (k3, not estimated, keeps ``stereo.json``'s stated σ, or
    the default figure's), and the rig's: ``stereo.R = R_lr^T``, ``stereo.T = -R_lr^T t_lr``
    with the Pose3 perturbation ``(ω, v)`` in the rig's own frame give ``δrvec = -ω`` and
    ``δT = -v - [T']ω`` (``T' = R_lr^T t_lr``)."""
    C_l, C_r, C_rig = (np.asarray(c, float) for c in covariance)
    base = stereo.uncertainty or default_uncertainty(stereo)
    K_std, dist_std = [], []
    for c, side in ((C_l, "left"), (C_r, "right")):
        sd = np.sqrt(np.clip(np.diag(c), 0.0, None))
        K_std.append(sd[[0, 1, 3, 4]])
        k3 = float(getattr(base, f"dist_std_{side}")[4])
        dist_std.append(np.array([*sd[5:9], k3]))
    T_lr = head[2]
    Tp = T_lr[:3, :3].T @ T_lr[:3, 3]
    J = np.zeros((6, 6))  # (rvec, T) from (ω, v)
    J[:3, :3] = -np.eye(3)
    J[3:, :3] = -skew(Tp)
    J[3:, 3:] = -np.eye(3)
    C = J @ C_rig @ J.T
    sd = np.sqrt(np.clip(np.diag(C), 0.0, None))
    return CalibrationUncertainty(
        K_std[0],
        dist_std[0],
        K_std[1],
        dist_std[1],
        sd[:3],
        sd[3:],
        float(rms_px),
        method="the survey adjustment's marginals",
    )


def refined_head(
    stereo: StereoCalibration,
    head: Head | None,
    covariance: tuple[Array, Array, Array] | None = None,
    rms_px: float = 0.0,
) -> StereoCalibration:
    """``stereo`` with the survey's self-calibrated camera matrices, rig and lens terms (its
    k3 and image size kept; the residual lens terms are added to ``stereo.json``'s, a first-order
    approximation as they are small), and with ``covariance`` (the adjustment's marginals) its
    uncertainty block."""
    if head is None:
        return stereo
    K_l, K_r, T_lr, d_l, d_r = head
    T_rl = np.linalg.inv(T_lr)
    dist = []
    for base, d in ((stereo.dist_left, d_l), (stereo.dist_right, d_r)):
        out = np.asarray(base, float).copy()
        out[:4] += d
        dist.append(out)
    return StereoCalibration(
        stereo.image_size,
        K_l,
        dist[0],
        K_r,
        dist[1],
        T_rl[:3, :3],
        T_rl[:3, 3],
        source=f"{stereo.source} (refined by the survey)",
        uncertainty=(
            None if covariance is None else head_uncertainty(stereo, head, covariance, rms_px)
        ),
    )
