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


@njit(cache=True)
def outline_prefilter(pts, starts, shape, min_area, border_only):
    """The cheap tests of :func:`measure.detect._discs` on outlines concatenated in
    ``pts`` (M, 2) (outline k: rows ``starts[k]`` … ``starts[k + 1]``; the last runs to
    the end): box, border contact and area (``cv2.boundingRect`` and ``cv2.contourArea``;
    integer vertices, so the same values) and, away from the border, compactness.
    Returns which pass, their boxes (x, y, w, h) and whether each touches the border."""
    H, W = shape
    n = starts.shape[0]
    ok = np.zeros(n, np.bool_)
    boxes = np.zeros((n, 4), np.int64)
    border = np.zeros(n, np.bool_)
    for k in range(n):
        s = starts[k]
        e = starts[k + 1] if k + 1 < n else pts.shape[0]
        x0, y0, x1, y1 = pts[s, 0], pts[s, 1], pts[s, 0], pts[s, 1]
        a00 = 0.0
        px, py = np.float64(pts[e - 1, 0]), np.float64(pts[e - 1, 1])
        for i in range(s, e):
            x, y = pts[i, 0], pts[i, 1]
            x0, x1, y0, y1 = min(x0, x), max(x1, x), min(y0, y), max(y1, y)
            a00 += px * y - py * x
            px, py = np.float64(x), np.float64(y)
        w, h = x1 - x0 + 1, y1 - y0 + 1
        boxes[k, 0], boxes[k, 1], boxes[k, 2], boxes[k, 3] = x0, y0, w, h
        if w * h < min_area:
            continue
        border[k] = x0 == 0 or y0 == 0 or x0 + w == W or y0 + h == H
        if border[k] != border_only:
            continue
        area = abs(a00 * 0.5)
        if area < min_area or area > 0.5 * H * W:
            continue
        if not border[k] and (
            area < 0.5 * w * h
            or min(w, h) < 0.3 * max(w, h)
            or 4.0 * math.pi * area < 0.45 * (e - s) ** 2  # ragged: a disc's is about 0.8
        ):
            continue
        ok[k] = True
    return ok, boxes, border
