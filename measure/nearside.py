"""Near-side check: edge points where a camera looks steeply over the rim.

On the side of the hole nearest to a camera, the image edge is where the rim *occludes* the
bore: the camera looks past the rim into the hole. For a sharp rim that silhouette is the
rim itself, but for a chamfered or rounded rim it is where the line of sight grazes the rim
profile, and that moves with the viewing angle: a camera looking at 41° to the axis past a
45° chamfer sees the chamfer as a sliver under a pixel wide, its outer and inner rims merge
into one image edge, and that edge is not where the other camera sees the bore edge. The
two views then triangulate to a point tens of micrometres off the circle (mostly in depth)
over a contiguous sector, which can be a third of the contour: too much for a per-point
robust fit to be sure to reject.

The check: the *rim view angle* of a point for a camera is the angle between the hole axis
and the line of sight in the plane through the axis and the point (positive on the camera's
side of the hole, where the camera looks over the rim). Points with a rim view angle above
a threshold for either camera are *suspect*. The plain robust fit's inliers that are not
suspect are refitted (from the plain fit, so burrs and false edges it rejected stay out),
and the suspect points are compared with that circle sector by sector (10° of azimuth): a
sector whose *median* residual (height over the plane, radial deviation) is more than
2.5 point standard deviations off is a systematic offset, not noise, and is dropped; the
circle is then refitted without it. Without a chamfer the sectors agree and the plain fit
is returned unchanged.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from measure.circle import Circle3D, _sigma, fit_circle_3d
from measure.circle_kernels import off_sectors, rim_view_angles_max

#: fewer safe points than this fraction of the usable ones: the check is skipped
MIN_SAFE_FRACTION = 0.4
MIN_SAFE_POINTS = 12
#: azimuth sectors of the consistency test, and when a sector's median residual is "off"
SECTOR_DEG = 10.0
SECTOR_MIN_POINTS = 5
SECTOR_LIMIT_SIGMA = 2.5


def rim_view_angles(
    points: np.ndarray, center: np.ndarray, normal: np.ndarray, cameras: np.ndarray
) -> np.ndarray:
    """Rim view angle (rad) of each point (N, 3) for each camera centre (K, 3); (N, K).

    The angle between the hole axis ``normal`` (unit, toward the cameras) and the line of
    sight from the point to the camera, measured in the plane through the axis and the
    point; positive where the camera is on the point's side of the hole (it looks over the
    rim there), negative on the far side. Points and centres in one frame (metres).
    """
    d = points - center
    radial = d - np.outer(d @ normal, normal)
    radial /= np.maximum(np.linalg.norm(radial, axis=1), 1e-300)[:, None]
    out = np.empty((len(points), len(cameras)))
    for k, cam in enumerate(np.asarray(cameras, dtype=float).reshape(-1, 3)):
        sight = cam - points
        out[:, k] = np.arctan2(np.einsum("ij,ij->i", sight, radial), sight @ normal)
    return out


def _residuals(points: np.ndarray, c: Circle3D) -> tuple[np.ndarray, ...]:
    """Height over the circle plane, radial deviation and azimuth of each point."""
    d = points - c.center
    h = d @ c.normal
    q = d - np.outer(h, c.normal)
    ref = np.array([1.0, 0.0, 0.0]) if abs(c.normal[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    u = np.cross(c.normal, ref)
    u /= np.linalg.norm(u)
    v = np.cross(c.normal, u)
    return h, np.linalg.norm(q, axis=1) - c.radius, np.arctan2(q @ v, q @ u)


def _off_sectors(
    h: np.ndarray, dr: np.ndarray, phi: np.ndarray, mask: np.ndarray, sigma: float
) -> np.ndarray:
    """Points of ``mask`` in azimuth sectors whose median residual is off the circle.

    A sector (``SECTOR_DEG`` of azimuth) is off when the median of its points' residual
    vector (h, ρ − r) is longer than ``SECTOR_LIMIT_SIGMA`` point standard deviations: a
    systematic offset, not noise (the median of a sector's dozens of points has a small
    fraction of the points' spread).
    """
    k = np.floor((phi + np.pi) / np.deg2rad(SECTOR_DEG)).astype(np.int64)
    return off_sectors(
        np.ascontiguousarray(h, np.float64),
        np.ascontiguousarray(dr, np.float64),
        k,
        np.ascontiguousarray(mask, np.bool_),
        SECTOR_MIN_POINTS,
        SECTOR_LIMIT_SIGMA * sigma,
    )


def fit_with_near_side_check(
    points: np.ndarray,
    weights: np.ndarray,
    cameras: np.ndarray,
    max_angle_deg: float,
    cost: str = "orthogonal",
    reject_sigma: float = 3.5,
    min_reject_m: float = 1e-6,
) -> tuple[Circle3D, int]:
    """Robust circle fit that drops near-side sectors disagreeing with the rest.

    Args:
        points: triangulated edge points (N, 3), metres, the cameras' frame.
        weights: per-point weights (N,), zero for points not to fit.
        cameras: camera centres (K, 3) in the same frame.
        max_angle_deg: points with a rim view angle above this for any camera are suspect.
        cost, reject_sigma, min_reject_m: as in :func:`measure.fit_circle_3d`.

    Returns:
        The circle and the number of suspect points dropped (also counted in its
        ``n_rejected`` and cleared in its ``inliers``).
    """
    w = np.asarray(weights, dtype=float)
    kw = {"cost": cost, "reject_sigma": reject_sigma, "min_reject_m": min_reject_m}
    plain = fit_circle_3d(points, w, **kw)
    usable = (w > 0) & np.all(np.isfinite(points), axis=1)
    ang = rim_view_angles_max(
        np.ascontiguousarray(points, dtype=np.float64).reshape(-1, 3),
        np.asarray(plain.center, dtype=np.float64).reshape(3),
        np.asarray(plain.normal, dtype=np.float64).reshape(3),
        np.ascontiguousarray(cameras, dtype=np.float64).reshape(-1, 3),
    )
    suspect = usable & (ang > np.deg2rad(max_angle_deg))
    # the reference: the plain fit's inliers off the suspect sectors (the plain fit has
    # already rejected burrs and false edges), refitted from the plain fit
    safe = usable & ~suspect & plain.inliers
    if not suspect.any() or safe.sum() < max(MIN_SAFE_POINTS, MIN_SAFE_FRACTION * usable.sum()):
        return plain, 0
    ref = fit_circle_3d(points, w * safe, start=plain, robust=False, **kw)
    h, dr, phi = _residuals(points, ref)
    d = np.hypot(h, dr)
    sigma = _sigma(d[ref.inliers], min_reject_m / reject_sigma)
    dropped = suspect & _off_sectors(h, dr, phi, suspect, sigma)
    if not (dropped & plain.inliers).any():
        return plain, 0  # the plain fit has rejected them already
    final = fit_circle_3d(points, w * ~dropped, start=ref, **kw)
    n_drop = int(dropped.sum())
    return replace(final, n_rejected=final.n_rejected + n_drop), n_drop
