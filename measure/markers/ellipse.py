"""Ellipse fit to sub-pixel edge points, with the centre's standard deviation.

A direct least-squares conic fit constrained to an ellipse (Fitzgibbon, Pilu & Fisher 1999, in
the numerically stable form of Halíř & Flusser 1998) starts a Gauss-Newton refinement of the
geometric parameters ``(cx, cy, a, b, θ)`` on the Sampson distance (the first-order
orthogonal distance), which removes the algebraic fit's bias; edge points farther than 3.5σ
are dropped once. The centre's covariance is ``s² (JᵀJ)⁻¹`` of the last step, ``s`` the RMS
distance of the points kept.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class EllipseFit:
    """``center`` (2,), semi-axes ``a >= b``, ``angle`` (rad, of ``a`` from +x), the centre's
    covariance ``cov_center`` (2, 2), RMS point distance ``rms`` and points used ``n``."""

    center: np.ndarray
    a: float
    b: float
    angle: float
    cov_center: np.ndarray
    rms: float
    n: int

    def opencv(self) -> tuple[tuple[float, float], tuple[float, float], float]:
        """As OpenCV writes a rotated rectangle: ((cx, cy), (major, minor) full axes, deg)."""
        c = (float(self.center[0]), float(self.center[1]))
        return c, (2.0 * self.a, 2.0 * self.b), float(np.degrees(self.angle))

    def point(self, t: np.ndarray, scale: float = 1.0) -> np.ndarray:
        """Points (k, 2) at parameter ``t`` of the ellipse scaled by ``scale`` about its centre."""
        c, s = np.cos(self.angle), np.sin(self.angle)
        x, y = scale * self.a * np.cos(t), scale * self.b * np.sin(t)
        return self.center + np.stack([c * x - s * y, s * x + c * y], axis=-1)


def direct_fit(pts: np.ndarray) -> np.ndarray | None:
    """Conic coefficients ``(A, B, C, D, E, F)`` of ``A x² + B xy + C y² + D x + E y + F = 0``
    (Halíř-Flusser direct ellipse fit); None when the points hold no ellipse."""
    x, y = pts[:, 0], pts[:, 1]
    D1 = np.stack([x * x, x * y, y * y], axis=1)
    D2 = np.stack([x, y, np.ones_like(x)], axis=1)
    S1, S2, S3 = D1.T @ D1, D1.T @ D2, D2.T @ D2
    try:
        T = -np.linalg.solve(S3, S2.T)
    except np.linalg.LinAlgError:
        return None
    M = S1 + S2 @ T
    M = np.array([M[2] / 2.0, -M[1], M[0] / 2.0])
    _w, v = np.linalg.eig(M)
    v = np.real(v)
    cond = 4.0 * v[0] * v[2] - v[1] ** 2
    ok = np.flatnonzero(cond > 0)
    if len(ok) == 0:
        return None
    a1 = v[:, ok[0]]
    return np.concatenate([a1, T @ a1])


def conic_params(coef: np.ndarray) -> tuple[float, float, float, float, float] | None:
    """``(cx, cy, a, b, angle)`` of an ellipse conic; None when it is not a real ellipse."""
    A, B, C, D, E, F = coef
    den = B * B - 4 * A * C
    if den >= 0:
        return None
    cx = (2 * C * D - B * E) / den
    cy = (2 * A * E - B * D) / den
    M = np.array([[A, B / 2], [B / 2, C]])
    f0 = F + 0.5 * (D * cx + E * cy)  # value of the conic at the centre
    w, v = np.linalg.eigh(M)
    if f0 == 0 or np.any(-f0 / w <= 0):
        return None
    axes = np.sqrt(-f0 / w)  # axis along each eigenvector
    i = int(np.argmax(axes))
    ang = float(np.arctan2(v[1, i], v[0, i]))
    return float(cx), float(cy), float(axes[i]), float(axes[1 - i]), ang


def _sampson(p: np.ndarray, pts: np.ndarray) -> np.ndarray:
    """Sampson distances (n,) of ``pts`` from the ellipse ``p``; ``p`` (k, 5): (k, n)."""
    cx, cy, a, b, th = (p[..., i, None] for i in range(5))
    c, s = np.cos(th), np.sin(th)
    dx, dy = pts[:, 0] - cx, pts[:, 1] - cy
    xr, yr = c * dx + s * dy, -s * dx + c * dy
    F = (xr / a) ** 2 + (yr / b) ** 2 - 1.0
    g = 2.0 * np.hypot(xr / (a * a), yr / (b * b))
    return F / g


_STEPS = np.array([1e-4, 1e-4, 1e-4, 1e-4, 1e-6])


def _gauss_newton(p: np.ndarray, pts: np.ndarray, iters: int) -> tuple[np.ndarray, np.ndarray]:
    JtJ = np.eye(5)
    for _ in range(iters):
        # the distances at p and at p moved by each step, in one evaluation (6, n)
        q = np.repeat(p[None], 6, axis=0)
        q[1:] += np.diag(_STEPS)
        rq = _sampson(q, pts)
        r = rq[0]
        J = np.ascontiguousarray(((rq[1:] - r) / _STEPS[:, None]).T)  # (n, 5), as BLAS had it
        JtJ = J.T @ J
        try:
            dp = -np.linalg.solve(JtJ, J.T @ r)
        except np.linalg.LinAlgError:
            break
        p = p + dp
        if np.all(np.abs(dp[:4]) < 1e-5):
            break
    return p, JtJ


def fit_ellipse(pts: np.ndarray, refine: bool = True) -> EllipseFit | None:
    """Fit an ellipse to edge points (n, 2); None when fewer than 8 points or no ellipse.
    ``refine`` False: the direct fit only (no outlier rejection, no covariance: zeros)."""
    pts = np.asarray(pts, dtype=float)
    if len(pts) < 8:
        return None
    mu = pts.mean(axis=0)
    scale = float(np.sqrt(np.mean(np.sum((pts - mu) ** 2, axis=1)))) or 1.0
    coef = direct_fit((pts - mu) / scale)
    if coef is None:
        return None
    par = conic_params(coef)
    if par is None:
        return None
    cx, cy, a, b, ang = par
    p = np.array([cx * scale + mu[0], cy * scale + mu[1], a * scale, b * scale, ang])
    if not refine:
        return EllipseFit(p[:2].copy(), p[2], p[3], ang, np.zeros((2, 2)), 0.0, len(pts))
    p, _ = _gauss_newton(p, pts, 4)
    r = _sampson(p, pts)
    sigma = 1.4826 * float(np.median(np.abs(r))) + 1e-6
    keep = np.abs(r) < 3.5 * max(sigma, 0.02)
    if keep.sum() < 8:
        return None
    pts = pts[keep]
    p, JtJ = _gauss_newton(p, pts, 2)
    r = _sampson(p, pts)
    rms = float(np.sqrt(np.mean(r * r)))
    dof = max(len(pts) - 5, 1)
    try:
        cov = np.linalg.inv(JtJ) * float(r @ r) / dof
    except np.linalg.LinAlgError:
        return None
    a_, b_, th = float(p[2]), float(p[3]), float(p[4])
    if a_ < 0:
        a_ = -a_
    if b_ < 0:
        b_ = -b_
    if b_ > a_:
        a_, b_, th = b_, a_, th + np.pi / 2
    th = float((th + np.pi / 2) % np.pi - np.pi / 2)
    return EllipseFit(p[:2].copy(), a_, b_, th, cov[:2, :2].copy(), rms, len(pts))
