"""Tests of a region's outline (pixels, as OpenCV's contours): does it follow an ellipse, and
the outline without the concave bites something inside the bore takes out of it."""

from __future__ import annotations

import cv2
import numpy as np


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
    """Does the outline (N, 2) (away from the image border) follow an ellipse?"""
    if border:
        H, W = shape
        keep = (pts[:, 0] > 0) & (pts[:, 1] > 0) & (pts[:, 0] < W - 1) & (pts[:, 1] < H - 1)
        pts = pts[keep]
    if len(pts) < 12:
        return False
    (cx, cy), (a2, b2), ang = cv2.fitEllipse(pts.astype(np.float32))
    if not np.isfinite(a2 + b2) or min(a2, b2) <= 2 or min(a2, b2) / max(a2, b2) < 0.35:
        return False
    t = np.deg2rad(ang)
    d = pts - (cx, cy)
    u = d[:, 0] * np.cos(t) + d[:, 1] * np.sin(t)
    v = -d[:, 0] * np.sin(t) + d[:, 1] * np.cos(t)
    rel = np.abs(np.hypot(u / (a2 / 2), v / (b2 / 2)) - 1.0)
    tol = max(0.06, 1.5 / (0.5 * min(a2, b2)))
    return float(np.median(rel)) < tol / 2 and float(np.mean(rel < tol)) > 0.6
