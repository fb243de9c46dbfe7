"""Tests of a region's outline (pixels, as OpenCV's contours): does it follow an ellipse, and
the outline without the concave bites something inside the bore takes out of it."""

from __future__ import annotations

import math

import cv2
import numpy as np
from numba import njit


def without_bites(contour: np.ndarray, min_depth_px: float = 1.5) -> np.ndarray | None:
    """The outline (N, 2) without its concave bites deeper than ``min_depth_px``.

    Something bright inside the bore that touches the rim in the image (a screw head at a
    tilt) bites into the dark region; the rest of the outline still follows the rim.
    Returns ``None`` when the bites take half the outline or more.
    """
    c = contour.reshape(-1, 1, 2).astype(np.int32)
    if len(c) < 8:
        return None
    try:
        hull = cv2.convexHull(c, returnPoints=False)
        defects = cv2.convexityDefects(c, hull)
    except cv2.error:
        return None
    keep = np.ones(len(c), dtype=bool)
    if defects is not None:
        for start, end, _, depth in defects.reshape(-1, 4):
            if depth / 256.0 > min_depth_px:
                if start <= end:
                    keep[start + 1 : end] = False
                else:
                    keep[start + 1 :] = False
                    keep[:end] = False
    if keep.sum() < 0.5 * len(c):
        return None
    return c[keep, 0].astype(np.float64)


def disc_like(pts: np.ndarray, shape: tuple[int, int], border: bool) -> bool:
    """Does the outline (N, 2) (away from the image border) follow an ellipse?

    ``pts`` may be float or OpenCV's int32 contour points (then used as they are)."""
    pts = pts.reshape(-1, 2)
    if border:
        H, W = shape
        keep = (pts[:, 0] > 0) & (pts[:, 1] > 0) & (pts[:, 0] < W - 1) & (pts[:, 1] < H - 1)
        pts = pts[keep]
    n = len(pts)
    if n < 12:
        return False
    ell_pts = pts if pts.dtype in (np.int32, np.float32) else pts.astype(np.float32)
    (cx, cy), (a2, b2), ang = cv2.fitEllipse(ell_pts)
    if not math.isfinite(a2 + b2) or min(a2, b2) <= 2 or min(a2, b2) / max(a2, b2) < 0.35:
        return False
    t = math.radians(ang)
    tol = max(0.06, 1.5 / (0.5 * min(a2, b2)))
    median, within = _ellipse_fit(pts, cx, cy, math.cos(t), math.sin(t), 2.0 / a2, 2.0 / b2, tol)
    return median < tol / 2 and within > 0.6 * n


@njit(cache=True)
def _ellipse_fit(pts, cx, cy, c, s, ia, ib, tol):
    """Median of |ρ − 1| (ρ: each point's normalised radius on the ellipse centred at
    (cx, cy), axes at angle (c, s), inverse half axes ia, ib) and how many are below
    ``tol``; one compiled pass instead of a dozen array operations (the disc test runs
    ten times a pair)."""
    n = pts.shape[0]
    rel = np.empty(n)
    within = 0
    for i in range(n):
        dx, dy = pts[i, 0] - cx, pts[i, 1] - cy
        u = (dx * c + dy * s) * ia
        v = (dy * c - dx * s) * ib
        rel[i] = abs(np.sqrt(u * u + v * v) - 1.0)
        if rel[i] < tol:
            within += 1
    return np.median(rel), within
