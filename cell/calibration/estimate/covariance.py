"""The covariance of the adjustment's estimates: corner noise, and the arm's pose scatter.

Corner noise alone (``white``): ``s^2 (J^T J)^-1`` with ``s^2 = sum(r^2) / (n - p)``.

On a real arm the residuals of one view are not independent: the arm's pose at that view is
off by its repeatability and by what the kinematic model leaves out, which shifts all of the
view's corners together. That part is modelled as an independent error of each view's flange
pose, position ``sigma_m`` per axis and rotation ``sigma_rad`` per axis (about the flange's
origin, in ``base_link``), so a view's residuals have the covariance
``Omega_v = s^2 I + A_v Sigma A_v^T`` (``A_v``: the view's corners against its flange pose,
:func:`cell.calibration.estimate.model.predict` with ``flange_jac``). The estimate stays the
ordinary least-squares one with the sandwich ``B (sum_v J_v^T Omega_v J_v) B``, ``B = (J^T J)^-1``;
:func:`cell.calibration.estimate.solve.solve_calibration` then refits by generalised least squares
with ``Omega`` (:class:`ViewWhitening`) and states ``(J^T Omega^-1 J)^-1`` (:func:`gls_covariance`).

Unless given (the arm's repeatability, say), the scatter is estimated from the data by moments,
with one unknown: ``sigma_m``, the rotation being ``sigma_m / lever_m`` (0.5 m: an arm's
orientation error is about its position error over half a metre). The residual energy each
view's flange pose explains, ``sum_v |P_v r_v|^2`` (``P_v`` the projection on the columns of
``A_v``), has the expectation ``s^2 (6V - tr(H P)) + sigma_m^2 (tr(A^T A shape) - tr(H A shape
A^T))`` (``H`` the fit's hat matrix: the global unknowns absorb part of the noise and of the
scatter, computed exactly through ``G_v = A_v^T J_v``); ``s^2`` comes from the residuals left
after each view's own flange correction, over ``n - 6V - p + tr(H P)`` degrees of freedom.
Estimated in pixel space this stays well conditioned (a view's flange position and rotation
are nearly interchangeable, one at a time they are not). With too few views (``6V <= p``),
only the corner noise is modelled and the result says so.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

Array = NDArray[np.float64]


@dataclass(frozen=True)
class CovarianceResult:
    """The covariance (p x p), the corner noise ``s2_px`` (px^2) it used, the flange scatter
    (m, rad per axis; 0 when not modelled) and where that came from."""

    covariance: Array
    s2_px: float
    flange_sigma_m: float
    flange_sigma_rad: float
    source: str
    method: str = "sandwich (J^T J)^-1 J^T Omega J (J^T J)^-1 on the least-squares estimate"


def _inverse_normal(J: Array) -> Array:
    """``(J^T J)^-1`` with the columns scaled to one before inverting (m against rad)."""
    norms = np.linalg.norm(J, axis=0)
    Jn = J / norms
    B = np.linalg.inv(Jn.T @ Jn) / np.outer(norms, norms)
    return 0.5 * (B + B.T)


def white_covariance(J: Array, r: Array) -> CovarianceResult:
    """Corner noise only: ``s^2 (J^T J)^-1``, ``s^2`` from the residuals over ``n - p``."""
    n, p = J.shape
    s2 = float(r @ r) / (n - p)
    return CovarianceResult(s2 * _inverse_normal(J), s2, 0.0, 0.0, "not modelled", "s^2 (J^T J)^-1")


def flange_scatter_covariance(
    J: Array,
    r: Array,
    F: Array,
    rows_view: NDArray[np.int64],
    n_stereo: int,
    sigma_m: float | None = None,
    sigma_rad: float | None = None,
    lever_m: float = 0.5,
) -> CovarianceResult:
    """The sandwich covariance with each view's flange pose error (see the module docstring).

    ``J`` (n, p) free columns, ``r`` (n,) residuals, ``F`` (n, 6) each row against its view's
    flange pose error, ``rows_view`` (n,) the view of each row, ``n_stereo`` how many of the p
    columns are stereo extrinsics (they move no flange). ``sigma_m``/``sigma_rad``: given
    scatter (``None``: estimated); ``lever_m``: the rotation error is the position error over
    this length (m) when not given.
    """
    n, p = J.shape
    views = np.unique(rows_view)
    V = len(views)
    p_flange = p - n_stereo
    if p_flange >= 6 * V or n - 6 * V - n_stereo <= 0:
        white = white_covariance(J, r)
        return CovarianceResult(
            white.covariance,
            white.s2_px,
            0.0,
            0.0,
            f"not modelled: {V} views are too few to tell it from the {p_flange} unknowns",
        )
    shape = np.diag([1.0] * 3 + [1.0 / lever_m**2] * 3)  # Sigma = sigma_m^2 shape
    B = _inverse_normal(J)
    energy, info, e2, tr_hp, absorbed = 0.0, 0.0, 0.0, 0.0, 0.0
    Gs = []
    for v in views:
        sel = rows_view == v
        A, rv = F[sel], r[sel]
        Ninv = _inverse_normal(A)
        g = A.T @ rv
        xi = Ninv @ g
        e2 += float(np.sum((rv - A @ xi) ** 2))
        energy += float(g @ xi)  # |P_v r_v|^2: the residual the view's flange pose explains
        info += float(np.trace(A.T @ A @ shape))
        G = A.T @ J[sel]  # (6, p)
        Gs.append(G)
        tr_hp += float(np.trace(B @ G.T @ Ninv @ G))  # the fit's share of the views' spans
        absorbed += float(np.trace(B @ G.T @ shape @ G))  # the scatter the fit absorbed
    s2 = e2 / (n - 6 * V - p + tr_hp)
    var = (energy - s2 * (6 * V - tr_hp)) / (info - absorbed)
    st = float(np.sqrt(max(var, 0.0))) if sigma_m is None else float(sigma_m)
    sr = float(sigma_rad) if sigma_rad is not None else st / lever_m
    given = sigma_m is not None or sigma_rad is not None
    source = "given" if given else "estimated from the per-view residuals"
    Sigma = np.diag([st**2] * 3 + [sr**2] * 3)
    meat = s2 * (J.T @ J)
    for G in Gs:
        meat += G.T @ Sigma @ G
    cov = B @ meat @ B
    return CovarianceResult(0.5 * (cov + cov.T), s2, st, sr, source)


class ViewWhitening:
    """``Omega^(-1/2)`` of the residuals: per view ``(I - Q Q^T) / s + Q C Q^T`` with
    ``A_v = Q R`` (thin QR) and ``C = (s^2 I + R Sigma R^T)^(-1/2)``; applied to residuals (n,)
    or Jacobians (n, p), it makes the generalised least squares an ordinary one (weights fixed
    at the linearisation point)."""

    def __init__(
        self, F: Array, rows_view: NDArray[np.int64], s2: float, sigma_m: float, sigma_rad: float
    ) -> None:
        self.s = float(np.sqrt(s2))
        Sigma = np.diag([sigma_m**2] * 3 + [sigma_rad**2] * 3)
        self.blocks = []
        for v in np.unique(rows_view):
            sel = np.flatnonzero(rows_view == v)
            Q, R = np.linalg.qr(F[sel])
            w, U = np.linalg.eigh(s2 * np.eye(6) + R @ Sigma @ R.T)
            self.blocks.append((sel, Q, (U / np.sqrt(w)) @ U.T))

    def __call__(self, x: Array) -> Array:
        out = np.empty_like(x)
        for sel, Q, C in self.blocks:
            xs = x[sel]
            qx = Q.T @ xs
            out[sel] = (xs - Q @ qx) / self.s + Q @ (C @ qx)
        return out


def gls_covariance(Jw: Array, result: CovarianceResult) -> CovarianceResult:
    """The covariance of the generalised least-squares estimate, ``(J_w^T J_w)^-1`` with ``J_w``
    the whitened Jacobian at its solution (same noise and scatter as ``result``)."""
    return CovarianceResult(
        _inverse_normal(Jw),
        result.s2_px,
        result.flange_sigma_m,
        result.flange_sigma_rad,
        result.source,
        "generalised least squares weighted by Omega^-1, covariance (J^T Omega^-1 J)^-1",
    )
