"""Spatial circle fit by Levenberg–Marquardt.

Initial value (as published): centre = mean point, normal = least-squares plane normal
(smallest singular vector of the centred points), radius = mean distance to the centre. The
robust orthogonal fit starts instead from the algebraic circle (that plane, then the Kåsa
circle of the points projected into it), which is close to the optimum for a closed
contour: when 90 % of the points support it, it is taken without a first LM refinement.

Two costs:

- ``"orthogonal"`` (default) minimises the sum of squared *true orthogonal distances* of the
  points to the circle: for a point p, with h = n·(p − c) its height over the circle plane and
  ρ = |(p − c) − h n| its distance from the axis, d² = h² + (ρ − r)². The residual vector per
  point is (h, ρ − r), so every point weighs in metres and noise across or along the circle
  plane counts alike: this is the maximum-likelihood fit under isotropic point noise.
- ``"published"`` minimises Σ (|p − c|² − r²)² + (n·(p − c))², the published cost, which mixes a
  squared length (m²) with an unsquared one (m). The radial term is in effect scaled by 2r,
  so for millimetre holes the plane term dominates and the radius and centre are weighted
  arbitrarily; it is kept for the benchmark comparison.

The orthogonal cost is minimised by a small Levenberg–Marquardt loop written out in NumPy
(:func:`_lm_orthogonal`: six parameters, JᵀJ formed directly, the normal re-parametrised
about the current estimate at each step); from the algebraic circle it takes one or two
steps and about 0.1 ms per step for 1500 points, where ``scipy.optimize.least_squares``
spends about 1 ms per call on its own bookkeeping. A test checks that both reach the same
minimum. The published cost is solved with ``least_squares`` (numerical Jacobian).

Robustness: if less than 90 % of the points lie within 0.5 % of the radius (at least 10 µm)
of the (refined) start, a three-point RANSAC circle with more support replaces it, followed by
two iteratively reweighted passes with Cauchy weights; then iterative rejection of points
farther than
``reject_sigma`` robust standard deviations (MAD) from the circle, refitted with plain LM on
the inliers. The number rejected is reported.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares

from measure.circle_kernels import lm_orthogonal, orthogonal_distances
from measure.errors import FitError

CIRCLE_COSTS = ("orthogonal", "published")
#: consensus tolerance of the robust start: max(0.5 % of the radius, 10 µm)
RANSAC_TOL_FRAC = 0.005
RANSAC_TOL_MIN_M = 10e-6


@dataclass(frozen=True)
class Circle3D:
    """A fitted spatial circle (metres, in the frame of the input points).

    ``normal`` is a unit vector (sign: see :func:`fit_circle_3d`), ``rms_m`` the RMS orthogonal
    distance of the inliers, ``cov_center_radius`` the 4×4 covariance of (cx, cy, cz, r) in m²,
    ``cov_normal`` the 2×2 covariance of the normal's tilt (rad²) about two axes ⊥ normal.
    ``inliers`` marks the points kept.
    """

    center: np.ndarray
    normal: np.ndarray
    radius: float
    rms_m: float
    n_used: int
    n_rejected: int
    inliers: np.ndarray
    cov_center_radius: np.ndarray
    cov_normal: np.ndarray
    cost: str


def _basis(n: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Two unit vectors u = n × ref / |…| and v = n × u completing the unit normal ``n``
    (ref: the x axis, else the y axis); written out, ``np.cross`` costs 20 µs a call."""
    x, y, z = float(n[0]), float(n[1]), float(n[2])
    u = (0.0, z, -y) if abs(x) < 0.9 else (-z, 0.0, x)  # n × (1, 0, 0) or n × (0, 1, 0)
    k = 1.0 / np.sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2])
    u = (u[0] * k, u[1] * k, u[2] * k)
    v = (y * u[2] - z * u[1], z * u[0] - x * u[2], x * u[1] - y * u[0])
    return np.array(u), np.array(v)


def _unpack(x: np.ndarray, n0: np.ndarray, u: np.ndarray, v: np.ndarray):
    n = n0 + x[3] * u + x[4] * v
    return x[:3], n / np.linalg.norm(n), x[5]


def _residuals(x, pts, sw, n0, u, v, cost):
    c, n, r = _unpack(x, n0, u, v)
    d = pts - c
    h = d @ n
    if cost == "orthogonal":
        rho = np.linalg.norm(d - np.outer(h, n), axis=1)
        res = np.stack([h, rho - r], axis=1)
    else:
        res = np.stack([np.einsum("ij,ij->i", d, d) - r * r, h], axis=1)
    return (res * sw[:, None]).ravel()


def orthogonal_distance(
    pts: np.ndarray, center: np.ndarray, normal: np.ndarray, radius: float
) -> np.ndarray:
    """Distance (metres) of each point (N, 3) from the circle."""
    return orthogonal_distances(
        np.ascontiguousarray(pts, dtype=np.float64).reshape(-1, 3),
        np.asarray(center, dtype=np.float64).reshape(3),
        np.asarray(normal, dtype=np.float64).reshape(3),
        float(radius),
    )


def initial_circle(pts: np.ndarray, w: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """Mean point, least-squares plane normal, mean distance (the published initial value)."""
    c = (pts * w[:, None]).sum(axis=0) / w.sum()
    _, _, vt = np.linalg.svd((pts - c) * np.sqrt(w)[:, None], full_matrices=False)
    n = vt[2]
    r = float((np.linalg.norm(pts - c, axis=1) * w).sum() / w.sum())
    return c, n, r


def algebraic_circle(pts: np.ndarray, w: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """Algebraic circle: the least-squares plane (as :func:`initial_circle`, here from the
    eigenvectors of the 3 × 3 weighted scatter matrix), then the Kåsa circle of the points
    projected into it (a linear solve of x² + y² = 2 a x + 2 b y + k, by its 3 × 3 normal
    equations). Near the optimum for a closed contour, so the LM started from it
    converges in an iteration or two."""
    c0 = (w @ pts) / w.sum()
    d = pts - c0
    dw = d * w[:, None]
    _, vecs = np.linalg.eigh(dw.T @ d)  # ascending: the normal is the last column but two
    e0, e1, n = vecs[:, 2], vecs[:, 1], vecs[:, 0]
    x, y = d @ e0, d @ e1
    A = np.stack([2.0 * x, 2.0 * y, np.ones_like(x)], axis=1)
    Aw = A * w[:, None]
    try:
        a, b, k = np.linalg.solve(Aw.T @ A, Aw.T @ (x * x + y * y))
    except np.linalg.LinAlgError:
        return initial_circle(pts, w)
    r2 = k + a * a + b * b
    if not (np.isfinite(r2) and r2 > 0):
        return initial_circle(pts, w)
    return c0 + a * e0 + b * e1, n, float(np.sqrt(r2))


def _lm_orthogonal(pts, sw, c, n, r, max_iter: int = 100):
    """Levenberg–Marquardt on the orthogonal cost (points in any length unit).

    The normal is re-parametrised about the current estimate at every step, so each step
    is a plain 6-parameter solve of (JᵀJ + λ diag JᵀJ) δ = −Jᵀe; started from the
    algebraic circle it converges in two or three steps. Stops when the step would lower
    the cost by less than 1e-10 of itself (to first order) or is below 1e-10 of the radius.
    Returns centre, normal, radius, JᵀJ at the end, the cost eᵀe and the number of residuals.
    The loop is compiled (:func:`measure.circle_kernels.lm_orthogonal`).
    """
    c, n, r, A, cost = lm_orthogonal(
        np.ascontiguousarray(pts, np.float64),
        np.ascontiguousarray(sw, np.float64),
        np.ascontiguousarray(c, np.float64),
        np.ascontiguousarray(n, np.float64),
        float(r),
        max_iter,
    )
    return c, n, r, A, cost, 2 * len(pts)


def _solve(pts, w, c, n, r, cost):
    """One LM solve from (c, n, r); returns the circle and (JᵀJ, eᵀe, residual count)
    for the covariance, and the unit scale used."""
    # the orthogonal cost is homogeneous in length: work in millimetres for conditioning.
    # The published cost is not (m² mixed with m): evaluate it in SI units as specified.
    if cost == "orthogonal":
        k = 1e3
        cc, nn, rr, JtJ, ee, m = _lm_orthogonal(pts * k, np.sqrt(w), c * k, n, r * k)
        return cc / k, nn, rr / k, (JtJ, ee, m), k
    u, v = _basis(n)
    x0 = np.concatenate([c, [0.0, 0.0, r]])
    args = (pts, np.sqrt(w), n, u, v, cost)
    sol = least_squares(_residuals, x0, jac="2-point", args=args, method="lm")
    cc, nn, rr = _unpack(sol.x, n, u, v)
    return cc, nn, rr, (sol.jac.T @ sol.jac, 2.0 * sol.cost, sol.jac.shape[0]), 1.0


def circle_through(p1: np.ndarray, p2: np.ndarray, p3: np.ndarray):
    """Circles through point triples (K, 3) each: centres (K, 3), unit normals, radii."""
    a, b = p1 - p3, p2 - p3
    axb = np.cross(a, b)
    den = 2.0 * np.einsum("ij,ij->i", axb, axb)
    aa, bb = np.einsum("ij,ij->i", a, a), np.einsum("ij,ij->i", b, b)
    with np.errstate(divide="ignore", invalid="ignore"):
        c = p3 + np.cross(aa[:, None] * b - bb[:, None] * a, axb) / den[:, None]
        n = axb / np.sqrt(0.5 * den)[:, None]
    return c, n, np.linalg.norm(p1 - c, axis=1)


def ransac_circle(
    pts: np.ndarray,
    w: np.ndarray,
    r_guess: float,
    trials: int = 96,
    tol_frac: float = RANSAC_TOL_FRAC,
    tol_min_m: float = RANSAC_TOL_MIN_M,
    seed: int = 0,
) -> tuple[np.ndarray, np.ndarray, float, float]:
    """Best-supported circle through three points (support: points within
    max(``tol_frac`` × radius, ``tol_min_m``)).

    Returns centre, normal, radius and the supporting weight fraction. Seeded.
    """
    rng = np.random.default_rng(seed)
    idx = rng.integers(0, len(pts), size=(trials, 3))
    c, n, r = circle_through(pts[idx[:, 0]], pts[idx[:, 1]], pts[idx[:, 2]])
    ok = np.isfinite(r) & (r > 0.25 * r_guess) & (r < 4.0 * r_guess)
    if not ok.any():
        return c[0], n[0], float(r_guess), 0.0
    c, n, r = c[ok], n[ok], r[ok]
    d = pts[None, :, :] - c[:, None, :]
    h = np.einsum("kij,kj->ki", d, n)
    rho = np.sqrt(np.maximum(np.einsum("kij,kij->ki", d, d) - h * h, 0.0))
    dist = np.hypot(h, rho - r[:, None])
    support = ((dist < np.maximum(tol_frac * r, tol_min_m)[:, None]) * w[None, :]).sum(axis=1)
    k = int(np.argmax(support))
    return c[k], n[k], float(r[k]), float(support[k] / w.sum())


def _support(pts: np.ndarray, w: np.ndarray, c: np.ndarray, n: np.ndarray, r: float) -> float:
    """Weight fraction of the points within max(0.5 % of the radius, 10 µm) of the circle."""
    tol = max(RANSAC_TOL_FRAC * r, RANSAC_TOL_MIN_M)
    return float((w * (orthogonal_distance(pts, c, n, r) < tol)).sum() / w.sum())


def _sigma(d: np.ndarray, floor: float) -> float:
    """Robust σ of isotropic 2-D residuals from their distances (Rayleigh median)."""
    n = len(d)
    k = n // 2
    if n == 0:
        return max(float("nan"), floor)  # as np.median of nothing
    if n % 2:
        med = float(np.partition(d, k)[k])
    else:  # as np.median: the mean of the two middle values
        part = np.partition(d, [k - 1, k])
        med = 0.5 * float(part[k - 1] + part[k])
    return max(med / 1.1774, floor)


def fit_circle_3d(
    points: np.ndarray,
    weights: np.ndarray | None = None,
    cost: str = "orthogonal",
    robust: bool = True,
    reject_sigma: float = 3.5,
    min_reject_m: float = 1e-6,
    toward: np.ndarray | None = None,
    start: Circle3D | None = None,
) -> Circle3D:
    """Fit a circle to 3-D points (N, 3, metres) by LM; robust to outliers (see module doc).

    Args:
        points: the points, any frame, metres.
        weights: optional non-negative weight per point (zero-weight points are ignored).
        cost: ``"orthogonal"`` (default) or ``"published"``.
        robust: Cauchy-reweighted start and iterative rejection; ``False`` fits all points.
        reject_sigma: rejection threshold in robust standard deviations of the distance.
        min_reject_m: never reject points closer than this (metres).
        toward: if given, the normal is oriented to point toward this point (e.g. the
            camera centre, the origin of the camera frame); otherwise toward the origin.
        start: a circle known to be near the answer (e.g. a fit to a superset of the
            points); the robust start (RANSAC, reweighting) is then skipped and the
            rejection begins from it.

    Returns:
        :class:`Circle3D`. Raises :class:`FitError` for fewer than 6 usable points or a
        degenerate result.
    """
    if cost not in CIRCLE_COSTS:
        raise ValueError(f"cost must be one of {CIRCLE_COSTS}, got {cost!r}")
    pts_all = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    w_all = (
        np.ones(len(pts_all)) if weights is None else np.asarray(weights, dtype=np.float64).ravel()
    )
    if len(w_all) != len(pts_all):
        raise ValueError(f"{len(w_all)} weights for {len(pts_all)} points")
    usable = (w_all > 0) & np.all(np.isfinite(pts_all), axis=1)
    if usable.sum() < 6:
        raise FitError(f"only {int(usable.sum())} usable points, at least 6 needed")
    pts, w = pts_all[usable], w_all[usable]
    algebraic = start is None and robust and cost == "orthogonal"
    if start is not None:
        c, n, r = np.asarray(start.center, float), np.asarray(start.normal, float), start.radius
    elif algebraic:
        c, n, r = algebraic_circle(pts, w)
    else:
        c, n, r = initial_circle(pts, w)
    floor = min_reject_m / reject_sigma
    if robust and start is None:
        # the start (orthogonal cost: the algebraic circle, taken as it is when 90 % of the
        # points support it; else refined by LM); if a 3-point RANSAC circle has more
        # support within max(0.5 % of the radius, 10 µm) (a dented or partly false
        # contour), start from it
        own = _support(pts, w, c, n, r) if algebraic else 0.0
        if own < 0.9:
            c, n, r, *_ = _solve(pts, w, c, n, r, cost)
            own = _support(pts, w, c, n, r)
        if own < 0.9:
            rc, rn, rr, support = ransac_circle(pts, w, r)
            if support > own:
                c, n, r = rc, rn, rr
        # two Cauchy-weighted (IRLS) passes pull the start away from remaining outliers
        for _ in range(2 if own < 0.9 else 0):
            d = orthogonal_distance(pts, c, n, r)
            s = _sigma(d, floor)
            c, n, r, *_ = _solve(pts, w / (1.0 + (d / (2.385 * s)) ** 2), c, n, r, cost)
    inl = np.ones(len(pts), dtype=bool)
    if robust:
        d = orthogonal_distance(pts, c, n, r)
        inl = d < reject_sigma * _sigma(d, floor)
        if inl.sum() < 6:
            inl = np.ones(len(pts), dtype=bool)
    for _ in range(5 if robust else 1):
        c, n, r, system, k = _solve(pts[inl], w[inl], c, n, r, cost)
        if not robust:
            break
        d = orthogonal_distance(pts, c, n, r)
        new = d < reject_sigma * _sigma(d[inl], floor)
        if new.sum() < 6 or np.count_nonzero(new != inl) <= 0.005 * len(inl):
            break  # stable to within 0.5 % of the points
        inl = new
    if not (np.isfinite(r) and r > 0 and np.all(np.isfinite(c))):
        raise FitError(f"degenerate circle (radius {r!r})")
    target = np.zeros(3) if toward is None else np.asarray(toward, dtype=float)
    if n @ (target - c) < 0:
        n = -n
    d_in = orthogonal_distance(pts[inl], c, n, r)
    rms = float(np.sqrt(np.sum(w[inl] * d_in**2) / np.sum(w[inl])))
    cov_cr, cov_n = _covariance(system, k)
    inliers = np.zeros(len(pts_all), dtype=bool)
    inliers[np.flatnonzero(usable)[inl]] = True
    return Circle3D(
        center=c,
        normal=n,
        radius=float(r),
        rms_m=rms,
        n_used=int(inl.sum()),
        n_rejected=int((~inl).sum()),
        inliers=inliers,
        cov_center_radius=cov_cr,
        cov_normal=cov_n,
        cost=cost,
    )


def _covariance(system, k: float) -> tuple[np.ndarray, np.ndarray]:
    """Parameter covariance from the final Jacobian, s² (JᵀJ)⁻¹, back in metres."""
    JtJ, ee, m = system
    p = JtJ.shape[0]
    s2 = ee / max(m - p, 1)
    try:
        cov = np.linalg.inv(JtJ) * s2
    except np.linalg.LinAlgError:
        cov = np.full((p, p), np.nan)
    idx = [0, 1, 2, 5]
    return cov[np.ix_(idx, idx)] / k**2, cov[3:5, 3:5]
