"""The plain reference for the survey adjustment: ``scipy.optimize.least_squares`` (trust
region, sparse Jacobian pattern, LSMR) on the same residuals and priors as
:mod:`.solve_gtsam`, the head self-calibrated the same way (both cameras' fx, fy, cx, cy and
the rig), view 0 held by the same loose prior. Positions only (no covariance)."""

from __future__ import annotations

import numpy as np
from scipy.optimize import least_squares
from scipy.sparse import lil_matrix

from cell.referencing.survey.problem import Array, Head, SurveyProblem, predict
from cell.referencing.survey.solution import RawSolution
from cell.referencing.survey.solve_gtsam import DATUM_SIGMA
from robots.transforms import so3_exp

#: head unknowns: (fx, fy, cx, cy) per camera, the rig's rotation and translation, then the
#: lens terms (k1, k2, p1, p2) per camera
N_HEAD = 22


def _poses(problem: SurveyProblem, x: Array) -> Array:
    V = problem.n_views
    d = x[: 6 * V].reshape(V, 6)
    T = problem.poses0.copy()
    T[:, :3, :3] = problem.poses0[:, :3, :3] @ so3_exp(d[:, :3])
    T[:, :3, 3] += d[:, 3:]
    return T


def _head(problem: SurveyProblem, h: Array) -> Head:
    Ks = []
    for c in range(2):
        K = problem.K[c].copy()
        K[0, 0] += h[4 * c]
        K[1, 1] += h[4 * c + 1]
        K[0, 2] += h[4 * c + 2]
        K[1, 2] += h[4 * c + 3]
        Ks.append(K)
    T = problem.T_left_right.copy()
    T[:3, :3] = T[:3, :3] @ so3_exp(h[8:11])
    T[:3, 3] += h[11:14]
    return Ks[0], Ks[1], T, h[14:18], h[18:22]


def _split(problem: SurveyProblem, x: Array) -> tuple[Array, Array, Array]:
    V, n = problem.n_views, problem.n_markers
    return _poses(problem, x), x[6 * V : 6 * V + 3 * n].reshape(-1, 3), x[6 * V + 3 * n :]


def _residuals(x: Array, problem: SurveyProblem) -> Array:
    poses, points, h = _split(problem, x)
    r = [
        (
            (predict(problem, poses, points, _head(problem, h)) - problem.uv) / problem.sigma_px
        ).ravel()
    ]
    for b in problem.bars:
        d = np.linalg.norm(points[b.i] - points[b.j]) - b.length_m
        r.append(np.array([d / max(b.sigma_m, 1e-9)]))
    r.append(x[:6] / DATUM_SIGMA)
    sig = np.concatenate(
        [
            problem.K_sigma[0],
            problem.K_sigma[1],
            problem.rig_sigma,
            problem.dist_sigma[0],
            problem.dist_sigma[1],
        ]
    )
    r.append(h / np.maximum(sig, 1e-9))
    return np.concatenate(r)


def _sparsity(problem: SurveyProblem):
    V, n, k = problem.n_views, problem.n_markers, len(problem.uv)
    n_x = 6 * V + 3 * n + N_HEAD
    A = lil_matrix((2 * k + len(problem.bars) + 6 + N_HEAD, n_x), dtype=int)
    head0 = 6 * V + 3 * n
    for row in range(k):
        v, j, s = int(problem.view[row]), int(problem.marker[row]), int(problem.side[row])
        for r in (2 * row, 2 * row + 1):
            A[r, 6 * v : 6 * v + 6] = 1
            A[r, 6 * V + 3 * j : 6 * V + 3 * j + 3] = 1
            A[r, head0 + 4 * s : head0 + 4 * s + 4] = 1
            A[r, head0 + 14 + 4 * s : head0 + 18 + 4 * s] = 1
            if s == 1:
                A[r, head0 + 8 : head0 + 14] = 1
    for q, b in enumerate(problem.bars):
        A[2 * k + q, 6 * V + 3 * b.i : 6 * V + 3 * b.i + 3] = 1
        A[2 * k + q, 6 * V + 3 * b.j : 6 * V + 3 * b.j + 3] = 1
    base = 2 * k + len(problem.bars)
    for c in range(6):
        A[base + c, c] = 1
    for c in range(N_HEAD):
        A[base + 6 + c, head0 + c] = 1
    return A


def solve_scipy(problem: SurveyProblem) -> RawSolution:
    """Adjust ``problem`` with SciPy (module doc)."""
    V = problem.n_views
    x0 = np.concatenate([np.zeros(6 * V), problem.points0.ravel(), np.zeros(N_HEAD)])
    res = least_squares(
        _residuals,
        x0,
        args=(problem,),
        jac_sparsity=_sparsity(problem),
        method="trf",
        x_scale="jac",
        tr_solver="lsmr",
        xtol=1e-12,
        ftol=1e-12,
        gtol=1e-12,
        max_nfev=200,
    )
    chi2 = float(res.fun @ res.fun)
    dof = max(2 * len(problem.uv) + len(problem.bars) - 6 * V - 3 * problem.n_markers - 24, 1)
    poses, points, h = _split(problem, res.x)
    return RawSolution(points, poses, None, chi2, dof, int(res.nfev), _head(problem, h))
