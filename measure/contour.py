"""The closed hole contour of one image: lines through the centroid, gap filling, ellipse.

Sub-pixel edge points are expressed in polar form ``r(θ)`` about the region centroid. A
bundle of lines through the centroid (about one per pixel of arc) cuts the contour at two
points each (angles θ and θ + π), by linear interpolation along the contour. Where no edge
point lies near a line (a broken edge) the point is *filled*: short gaps by interpolation
along the contour, long gaps from a robust ellipse fitted to the rest. Points far from
that ellipse (burrs, false edges) are treated as missing too.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np

from measure.edge_kernels import curvature_polar, periodic_median

#: ``cv2.fitEllipse`` style: ((cx, cy), (full axis 1, full axis 2), angle in degrees)
Ellipse = tuple[tuple[float, float], tuple[float, float], float]


@dataclass(frozen=True)
class Contour:
    """Contour samples ordered by angle about the centroid (full-image pixels).

    ``filled`` marks samples interpolated over a gap; ``long_gap`` those filled from the
    ellipse over a long gap (they carry no measurement); ``ellipse`` is the robust
    image ellipse of the measured samples.
    """

    points_px: np.ndarray
    angles: np.ndarray
    filled: np.ndarray
    long_gap: np.ndarray
    ellipse: Ellipse
    n_outliers: int


def ellipse_distance(pts: np.ndarray, ell: Ellipse) -> np.ndarray:
    """Approximate signed distance (px) of points from an ellipse (radial, normalised)."""
    (cx, cy), (a2, b2), ang = ell
    t = math.radians(ang)
    ct, st = math.cos(t), math.sin(t)
    dx, dy = pts[:, 0] - cx, pts[:, 1] - cy
    u = dx * ct + dy * st
    v = dy * ct - dx * st
    rel = np.hypot(u * (2.0 / a2), v * (2.0 / b2))
    rad = np.hypot(u, v) / np.maximum(rel, 1e-12)  # ellipse radius along the ray
    return (rel - 1.0) * rad


def _median_abs(d: np.ndarray) -> float:
    """``np.median(np.abs(d))`` from one partial sort (``d`` not empty)."""
    a = np.abs(d)
    n = len(a)
    k = n // 2
    if n % 2:
        return float(np.partition(a, k)[k])
    part = np.partition(a, [k - 1, k])
    return float(0.5 * (part[k - 1] + part[k]))


def robust_ellipse(
    pts: np.ndarray, trials: int = 48, tol_px: float = 1.0, floor_px: float = 2.0, seed: int = 0
) -> tuple[Ellipse, np.ndarray]:
    """``cv2.fitEllipse`` made robust by RANSAC over the ordered contour.

    When 90 % of the points already lie within ``tol_px`` of the plain fit, RANSAC is
    skipped. Otherwise each trial fits an ellipse to six points, one from each sixth of the
    contour, and counts
    the points within ``tol_px``; the best consensus is refitted, then points within
    max(4σ, ``floor_px``) of it are the inliers. A contiguous false arc far from the rest (a
    reflection, a false edge) cannot win. A shallow dent (a burr over the rim) can look
    like an ellipse in one image; the 3-D circle fit, which needs a *circle*, sorts that
    out, so the floor is generous. Seeded, so results are repeatable.
    """
    n = len(pts)
    pts32 = pts.astype(np.float32)
    ell = cv2.fitEllipse(pts32)
    d = ellipse_distance(pts, ell)
    clean = np.count_nonzero(np.abs(d) < tol_px) >= 0.9 * n
    if n >= 24 and not clean:
        rng = np.random.default_rng(seed)
        bounds = np.linspace(0, n, 7).astype(int)
        best, best_score = ell, np.count_nonzero(np.abs(ellipse_distance(pts, ell)) < tol_px)
        for _ in range(trials):
            idx = [rng.integers(bounds[k], bounds[k + 1]) for k in range(6)]
            try:
                cand = cv2.fitEllipse(pts[idx].astype(np.float32))
            except cv2.error:
                continue
            if not np.all(np.isfinite(cand[1])) or min(cand[1]) <= 0:
                continue
            score = np.count_nonzero(np.abs(ellipse_distance(pts, cand)) < tol_px)
            if score > best_score:
                best, best_score = cand, score
        ell = best
        inl = np.abs(ellipse_distance(pts, ell)) < tol_px
        if inl.sum() >= 6:
            ell = cv2.fitEllipse(pts32[inl])
        d = ellipse_distance(pts, ell)
    sigma = 1.4826 * _median_abs(d)
    inl = np.abs(d) < max(4.0 * sigma, floor_px)
    n_in = np.count_nonzero(inl)
    if 6 <= n_in < n:  # (all of them: the refit is the fit it started from)
        ell = cv2.fitEllipse(pts32[inl])
        d = ellipse_distance(pts, ell)
        inl = np.abs(d) < max(4.0 * sigma, floor_px)
    ell = (
        (float(ell[0][0]), float(ell[0][1])),
        (float(ell[1][0]), float(ell[1][1])),
        float(ell[2]),
    )
    return ell, inl


def _ellipse_points(ell: Ellipse, centroid: np.ndarray, angles: np.ndarray) -> np.ndarray:
    """Where rays from ``centroid`` at ``angles`` meet the ellipse."""
    (cx, cy), (a2, b2), ang = ell
    t = np.deg2rad(ang)
    a, b = a2 / 2.0, b2 / 2.0
    c = np.array([np.cos(t), np.sin(t)])
    s = np.array([-np.sin(t), np.cos(t)])
    p0 = centroid - (cx, cy)
    u0, v0 = p0 @ c, p0 @ s
    dirs = np.stack([np.cos(angles), np.sin(angles)], axis=1)
    du, dv = dirs @ c, dirs @ s
    A = (du / a) ** 2 + (dv / b) ** 2
    B = 2 * (u0 * du / a**2 + v0 * dv / b**2)
    C = (u0 / a) ** 2 + (v0 / b) ** 2 - 1.0
    t_hit = (-B + np.sqrt(np.maximum(B * B - 4 * A * C, 0.0))) / (2 * A)
    return centroid + t_hit[:, None] * dirs


def _wrap(a: np.ndarray) -> np.ndarray:
    """Angles (rad) wrapped to [−π, π)."""
    return (a + np.pi) % (2.0 * np.pi) - np.pi


def _polar_clean(r: np.ndarray, window: int = 9) -> np.ndarray:
    """Mask of samples within 1 px of a running median of r (sorted by angle, periodic)."""
    n = len(r)
    if n < window:
        return np.ones(n, dtype=bool)
    med = periodic_median(np.ascontiguousarray(r, np.float64), window)
    return np.abs(r - med) < 1.0


def curvature_correction(pts: np.ndarray, ell: Ellipse, sigma_px: float) -> np.ndarray:
    """Undo the inward shift of gradient maxima on a curved blurred edge.

    A Gaussian-blurred edge of curvature κ has its gradient maximum displaced toward the
    centre of curvature by σ²κ/2 (to first order). Each point moves back along the
    ellipse's outward normal by that amount; κ comes from the image ellipse.
    """
    (cx, cy), (a2, b2), ang = ell
    t = math.radians(ang)
    c, s = math.cos(t), math.sin(t)
    a, b = a2 / 2.0, b2 / 2.0
    dx, dy = pts[:, 0] - cx, pts[:, 1] - cy
    u = dx * c + dy * s
    v = dy * c - dx * s
    phi = np.arctan2(v / b, u / a)
    cp, sp = np.cos(phi), np.sin(phi)
    kappa = a * b / (a * a * sp**2 + b * b * cp**2) ** 1.5
    nu, nv = cp / a, sp / b  # outward normal ∝ (u/a², v/b²)
    shift = (0.5 * sigma_px**2) * kappa / np.hypot(nu, nv)
    out = np.empty_like(pts)
    out[:, 0] = pts[:, 0] + shift * (nu * c - nv * s)
    out[:, 1] = pts[:, 1] + shift * (nu * s + nv * c)
    return out


def build_contour(
    edge_px: np.ndarray,
    centroid_px: tuple[float, float],
    arc_step_px: float = 1.0,
    short_gap_px: float = 4.0,
    max_points: int = 2048,
    blur_sigma_px: float = 0.0,
) -> Contour | None:
    """Resample edge points along lines through the centroid; fill gaps; fit the ellipse."""
    if len(edge_px) < 12:
        return None
    c = np.asarray(centroid_px, dtype=np.float64)
    d = edge_px - c
    theta = np.arctan2(d[:, 1], d[:, 0])
    order = np.argsort(theta)
    theta, r, pts = theta[order], np.hypot(d[:, 0], d[:, 1])[order], edge_px[order]
    ok = _polar_clean(r)
    theta, r, pts = theta[ok], r[ok], pts[ok]
    if len(theta) < 12:
        return None
    ell, inl = robust_ellipse(pts)
    if blur_sigma_px > 0:  # curvature_correction, and the points' polar form again
        (ex, ey), (a2, b2), ang = ell
        t = math.radians(ang)
        pts, theta, r = curvature_polar(np.ascontiguousarray(pts), ex, ey, a2 / 2.0, b2 / 2.0,
                                        math.cos(t), math.sin(t), float(blur_sigma_px),
                                        float(c[0]), float(c[1]))  # fmt: skip
    n_out = int((~inl).sum())
    theta, r = theta[inl], r[inl]
    r_mean = float(np.mean(r))
    n_lines = min(max(round(math.pi * r_mean / arc_step_px), 24), max_points // 2)
    ang = -np.pi + np.pi * np.arange(2 * n_lines) / n_lines
    # angular distance from each line to the nearest measured sample (periodic)
    j = np.searchsorted(theta, ang) % len(theta)
    jm = (j - 1) % len(theta)
    gap_a = np.abs(_wrap(ang - theta[j]))
    gap_b = np.abs(_wrap(ang - theta[jm]))
    span = np.abs(_wrap(theta[j] - theta[jm])) * r_mean  # bracketing gap, px
    filled = span > short_gap_px * 0.5 + arc_step_px
    long_gap = span > short_gap_px
    near = np.minimum(gap_a, gap_b) * r_mean
    filled &= near > 0.5 * arc_step_px
    long_gap &= near > 0.5 * arc_step_px
    r_int = np.interp(ang, theta, r, period=2 * np.pi)
    out = c + r_int[:, None] * np.stack([np.cos(ang), np.sin(ang)], axis=1)
    if long_gap.any():
        out[long_gap] = _ellipse_points(ell, c, ang[long_gap])
    return Contour(
        points_px=out, angles=ang, filled=filled, long_gap=long_gap, ellipse=ell, n_outliers=n_out
    )
