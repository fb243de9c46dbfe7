"""The survey adjustment with GTSAM, self-calibrating the head.

Variables: every view's left-camera pose ``X_v`` and right-camera pose ``Y_v``, every marker
``L_j``, each camera's calibration (``Cal3DS2``: fx, fy, skew, cx, cy, k1, k2, p1, p2) and the rig
``R = T_left_right``. Factors:

- ``GeneralSFMFactor2Cal3DS2``: a marker's ideal pixel (undistorted with ``stereo.json``'s lens
  model) in the left camera (``X_v``, ``L_j``, left calibration) or the right (``Y_v``, ...); the
  calibration's lens terms (k1, k2, p1, p2) start at zero and take up what ``stereo.json``'s
  lens model leaves;
- a rig factor per view (:func:`_rig_error`): ``Y_v = X_v R``, held tight (one rigid head);
- priors: both calibrations and the rig at ``stereo.json``'s values with its stated sigma, the
  skew at zero; the scale bars as range factors; view 0 loosely (the free datum, moved by
  :mod:`.gauge`).

A head whose calibration is off by its stated sigma bends a network adjusted with the head
held fixed by 100-300 um (its rig rotation, principal points and focal lengths); the views at
several distances and orientations determine them, and the scale then comes from the bars.
"""

from __future__ import annotations

import gtsam
import numpy as np
from gtsam.symbol_shorthand import C, L, R, X, Y
from scipy.linalg import cho_factor, cho_solve

from cell.referencing.errors import SurveyRefusedError
from cell.referencing.survey.problem import Array, SurveyProblem
from cell.referencing.survey.solution import RawSolution

#: the datum prior on view 0 (m and rad). It acts only on the network's six free rigid motions,
#: which absorb it exactly (no residual changes), and the gauge moves the result afterwards.
#: 1e-3 was loose against image noise weighed at its a posteriori 0.006 px: Levenberg-Marquardt
#: then crawled along the rigid motions (65 iterations, 6 s on the demo's network); 1e-5 gives
#: the same network (distances within 0.001 um) in 3 iterations, 0.5 s
DATUM_SIGMA = 1e-5
#: how tightly each view's right camera follows the rig (rad, m); 1e-8 left the normal
#: equations too ill-conditioned to factor on some networks (a six-hole cell, marker seed 5:
#: no step taken), 1e-6 changes the built-in cell's network by under 0.1 um
RIG_TIE_SIGMA = 1e-6
#: the skew's prior (px): none in a real sensor
SKEW_SIGMA = 1e-6
#: the numerical step of the rig factor's Jacobians (rad, m)
_H = 1e-7


#: the Huber loss's corner of the robust first adjustment (sigma)
HUBER_K = 3.0

#: an adjustment that made no step and whose variance factor is above this is refused
STUCK_VARIANCE_FACTOR = 100.0


def _calibration(K: Array) -> gtsam.Cal3DS2:
    return gtsam.Cal3DS2(K[0, 0], K[1, 1], K[0, 1], K[0, 2], K[1, 2], 0.0, 0.0, 0.0, 0.0)


def _K(cal: gtsam.Cal3DS2) -> Array:
    return np.asarray(cal.K(), float)


def _lens(cal: gtsam.Cal3DS2) -> Array:
    return np.array([cal.k1(), cal.k2(), cal.p1(), cal.p2()])


def _rig_error(this: gtsam.CustomFactor, values: gtsam.Values, H) -> np.ndarray:
    """``Logmap((X R)^-1 Y)`` (6,) of the factor's keys (X_v, Y_v, R); numerical Jacobians."""
    keys = [this.keys()[i] for i in range(3)]
    poses = [values.atPose3(k) for k in keys]

    def err(p: list[gtsam.Pose3]) -> np.ndarray:
        return gtsam.Pose3.Logmap(p[0].compose(p[2]).between(p[1]))

    e = err(poses)
    if H is not None:
        for i in range(3):
            J = np.zeros((6, 6))
            for k in range(6):
                d = np.zeros(6)
                d[k] = _H
                plus, minus = list(poses), list(poses)
                plus[i], minus[i] = poses[i].retract(d), poses[i].retract(-d)
                J[:, k] = (err(plus) - err(minus)) / (2 * _H)
            H[i] = J
    return e


def _priors(graph: gtsam.NonlinearFactorGraph, problem: SurveyProblem) -> None:
    for c in range(2):
        s, d = problem.K_sigma[c], problem.dist_sigma[c]
        sig = np.array([s[0], s[1], SKEW_SIGMA, s[2], s[3], *d])
        noise = gtsam.noiseModel.Diagonal.Sigmas(np.maximum(sig, 1e-9))
        graph.add(gtsam.PriorFactorCal3DS2(C(c), _calibration(problem.K[c]), noise))
    rig = gtsam.noiseModel.Diagonal.Sigmas(np.maximum(problem.rig_sigma, 1e-9))
    graph.add(gtsam.PriorFactorPose3(R(0), gtsam.Pose3(problem.T_left_right), rig))
    datum = gtsam.noiseModel.Isotropic.Sigma(6, DATUM_SIGMA)
    graph.add(gtsam.PriorFactorPose3(X(0), gtsam.Pose3(problem.poses0[0]), datum))
    for b in problem.bars:
        noise = gtsam.noiseModel.Isotropic.Sigma(1, max(b.sigma_m, 1e-9))
        graph.add(gtsam.RangeFactor3(L(b.i), L(b.j), b.length_m, noise))


def _graph(
    problem: SurveyProblem, robust: bool = False
) -> tuple[gtsam.NonlinearFactorGraph, gtsam.Values]:
    graph = gtsam.NonlinearFactorGraph()
    values = gtsam.Values()
    pix = gtsam.noiseModel.Isotropic.Sigma(2, problem.sigma_px)
    if robust:
        pix = gtsam.noiseModel.Robust.Create(gtsam.noiseModel.mEstimator.Huber.Create(HUBER_K), pix)
    for k in range(len(problem.uv)):
        v, j, s = int(problem.view[k]), int(problem.marker[k]), int(problem.side[k])
        pose = X(v) if s == 0 else Y(v)
        uv = problem.uv[k].reshape(2, 1)
        graph.add(gtsam.GeneralSFMFactor2Cal3DS2(uv, pix, pose, L(j), C(s)))
    tie = gtsam.noiseModel.Isotropic.Sigma(6, RIG_TIE_SIGMA)
    for v in range(problem.n_views):
        graph.add(gtsam.CustomFactor(tie, [X(v), Y(v), R(0)], _rig_error))
        values.insert(X(v), gtsam.Pose3(problem.poses0[v]))
        values.insert(Y(v), gtsam.Pose3(problem.poses0[v] @ problem.T_left_right))
    for j in range(problem.n_markers):
        values.insertPoint3(L(j), problem.points0[j])
    for c in range(2):
        values.insert(C(c), _calibration(problem.K[c]))
    values.insert(R(0), gtsam.Pose3(problem.T_left_right))
    _priors(graph, problem)
    return graph, values


def solve_gtsam(
    problem: SurveyProblem, covariance: bool = True, robust: bool = False
) -> RawSolution:
    """Adjust ``problem`` (module doc); ``covariance``: also the markers' joint covariance
    (3n, 3n) m² and the head's, at the problem's ``sigma_px`` (the caller weighs with the
    a posteriori centre noise, :mod:`cell.referencing.sigma`), inflated by the variance factor
    when it is above 1, never deflated (that would scale the scale bars' and the priors'
    information with the pixels'); ``robust``: the image residuals through a Huber loss
    (:data:`HUBER_K` sigma), so that a gross error (a misread marker, a view far off its
    plan) cannot pull the self-calibrated head with it before it is found."""
    graph, values = _graph(problem, robust=robust)
    params = gtsam.LevenbergMarquardtParams()
    params.setRelativeErrorTol(1e-10)
    params.setAbsoluteErrorTol(1e-10)
    params.setMaxIterations(100)
    opt = gtsam.LevenbergMarquardtOptimizer(graph, values, params)
    result = opt.optimize()
    n_obs = 2 * len(problem.uv) + len(problem.bars)
    dof = max(n_obs - 6 * problem.n_views - 3 * problem.n_markers - 24, 1)
    if opt.iterations() == 0 and 2.0 * graph.error(result) / dof > STUCK_VARIANCE_FACTOR:
        # Cholesky could not factor the normal equations: QR, slower, factors the system itself
        params.setLinearSolverType("MULTIFRONTAL_QR")
        opt = gtsam.LevenbergMarquardtOptimizer(graph, values, params)
        result = opt.optimize()
    if opt.iterations() == 0 and 2.0 * graph.error(result) / dof > STUCK_VARIANCE_FACTOR:
        raise SurveyRefusedError(
            "the adjustment", "could not move from its start (an ill-posed network)"
        )
    points = np.array([result.atPoint3(L(j)) for j in range(problem.n_markers)])
    poses = np.array([result.atPose3(X(v)).matrix() for v in range(problem.n_views)])
    cams = [result.atCal3DS2(C(c)) for c in range(2)]
    head = (_K(cams[0]), _K(cams[1]), result.atPose3(R(0)).matrix(), _lens(cams[0]), _lens(cams[1]))
    chi2 = 2.0 * graph.error(result)
    cov, head_cov = None, None
    if covariance:
        scale = max(chi2 / dof, 1.0)
        cov, head_cov = _covariances(problem, graph, result)
        cov, head_cov = cov * scale, tuple(c * scale for c in head_cov)
    return RawSolution(points, poses, cov, chi2, dof, int(opt.iterations()), head, head_cov)


def _covariances(
    problem: SurveyProblem, graph: gtsam.NonlinearFactorGraph, result: gtsam.Values
) -> tuple[Array, tuple[Array, Array, Array]]:
    """The markers' joint covariance (3n, 3n) and the head's (both calibrations, the rig) at
    ``result``: GTSAM's marginals, or, when its Cholesky cannot factor the graph (the rig tie
    and the skew prior weigh 1e12 against the pixels' 1e2-1e3: an IndeterminateSystemException
    on some networks), the same information matrix dense, scaled to a unit diagonal and
    factored by SciPy (:func:`_dense_covariances`); refused when neither factors."""
    keys = gtsam.KeyVector()
    for j in range(problem.n_markers):
        keys.append(L(j))
    try:
        marginals = gtsam.Marginals(graph, result)
        cov = marginals.jointMarginalCovariance(keys).fullMatrix()
        return cov, tuple(marginals.marginalCovariance(k) for k in (C(0), C(1), R(0)))
    except RuntimeError:  # gtsam's IndeterminateSystemException
        return _dense_covariances(problem, graph, result)


def _dense_covariances(
    problem: SurveyProblem, graph: gtsam.NonlinearFactorGraph, result: gtsam.Values
) -> tuple[Array, tuple[Array, Array, Array]]:
    """:func:`_covariances` from the dense information matrix ``H`` (markers, calibrations and
    rig first): ``D^-1/2 H D^-1/2`` (``D`` its diagonal) by Cholesky, then the first columns of
    its inverse."""
    n, nv = problem.n_markers, problem.n_views
    order = gtsam.Ordering()
    for k in [L(j) for j in range(n)] + [C(0), C(1), R(0)]:
        order.push_back(k)
    for v in range(nv):
        order.push_back(X(v))
        order.push_back(Y(v))
    H, _ = graph.linearize(result).hessian(order)
    d = np.sqrt(np.clip(np.diag(H), 1e-300, None))
    try:
        factor = cho_factor(H / d[:, None] / d[None, :])
    except np.linalg.LinAlgError:
        raise SurveyRefusedError(
            "the adjustment's covariance", "the network's information matrix is singular"
        ) from None
    m = 3 * n + 24  # the markers, the two calibrations (9 each) and the rig (6)
    E = np.zeros((len(d), m))
    E[np.arange(m), np.arange(m)] = 1.0
    inv = cho_solve(factor, E)[:m] / d[:m, None] / d[None, :m]
    inv = 0.5 * (inv + inv.T)
    o = 3 * n
    return inv[:o, :o], (inv[o : o + 9, o : o + 9], inv[o + 9 : o + 18, o + 9 : o + 18],
                         inv[o + 18 :, o + 18 :])  # fmt: skip
