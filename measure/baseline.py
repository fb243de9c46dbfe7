"""The OpenCV-only comparison pipeline of the accuracy benchmark.

Canny in each image, ``cv2.fitEllipse`` to the hole's edge pixels, triangulate the two
ellipse centres (``cv2.undistortPoints`` + ``cv2.triangulatePoints``), radius from the
ellipse's semi-major axis and the depth, normal from the axis ratio (tilt about the major
axis; of the two mirror solutions the one whose projection best matches the right ellipse).
Known weaknesses, on purpose: an ellipse centre is not the projected circle centre, pixel-
level edges, no outlier handling.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import cv2
import numpy as np

from measure.calibration import StereoCalibration
from measure.detect import check_image, find_candidates, to_gray
from measure.edges import hole_region, outline_band
from measure.errors import EdgeError, HoleNotFoundError
from measure.triangulate import triangulate_dlt


@dataclass(frozen=True)
class BaselineResult:
    """Centre (m), unit normal toward the camera and radius (m), LEFT camera frame."""

    center_m: np.ndarray
    normal: np.ndarray
    radius_m: float
    time_s: float


def _ellipse(img: np.ndarray, which: str):
    img = to_gray(img, which)
    full, small = check_image(img, which)
    cands = [c for c in find_candidates(small) if not c.touches_border]
    if not cands:
        raise HoleNotFoundError(which, "no disc-like region")
    region = hole_region(img, full, cands[0])
    x0, y0, w, h = region.roi
    roi = img[y0 : y0 + h, x0 : x0 + w]
    roi8 = (
        roi if roi.dtype == np.uint8 else (roi.astype(np.float32) * (255.0 / full)).astype(np.uint8)
    )
    edges = cv2.Canny(cv2.GaussianBlur(roi8, (5, 5), 1.0), 40, 100) > 0
    ys, xs = np.nonzero(edges & outline_band(region.mask, 3))
    if len(xs) < 6:
        raise EdgeError(f"{which} image edges", len(xs), 6)
    pts = np.stack([xs + x0, ys + y0], axis=1).astype(np.float32)
    return cv2.fitEllipse(pts)


def _normal_candidates(stereo: StereoCalibration, ell, center: np.ndarray) -> list[np.ndarray]:
    (cx, cy), (a1, a2), ang = ell
    major, minor = max(a1, a2), min(a1, a2)
    phi = np.deg2rad(ang if a1 >= a2 else ang + 90.0)
    p0 = stereo.normalized(np.array([[cx, cy]]), "left")[0]
    p1 = stereo.normalized(np.array([[cx + np.cos(phi), cy + np.sin(phi)]]), "left")[0]
    view = center / np.linalg.norm(center)
    m = np.array([p1[0] - p0[0], p1[1] - p0[1], 0.0])
    m -= (m @ view) * view
    m /= np.linalg.norm(m)
    tilt = float(np.arccos(np.clip(minor / major, 0.0, 1.0)))
    out = []
    for sgn in (1.0, -1.0):
        t = sgn * tilt
        n = -view * np.cos(t) + np.cross(m, -view) * np.sin(t)
        out.append(n / np.linalg.norm(n))
    return out


def measure_hole_opencv(
    left: np.ndarray, right: np.ndarray, stereo: StereoCalibration
) -> BaselineResult:
    """Measure a hole with the OpenCV-only baseline (see module doc)."""
    t0 = time.perf_counter()
    ell_l, ell_r = _ellipse(left, "left"), _ellipse(right, "right")
    cl = stereo.undistort_rectify(np.array([ell_l[0]]), "left")
    cr = stereo.undistort_rectify(np.array([ell_r[0]]), "right")
    center = triangulate_dlt(stereo, cl, cr)[0]
    f = stereo.K_left[0, 0]
    z_r = (stereo.R @ center + stereo.T)[2]
    radius = 0.25 * (max(ell_l[1]) * center[2] + max(ell_r[1]) * z_r) / f
    best, best_err = None, np.inf
    for n in _normal_candidates(stereo, ell_l, center):
        phi = np.linspace(0, 2 * np.pi, 36, endpoint=False)
        u = np.cross(n, [1.0, 0.0, 0.0])
        u /= np.linalg.norm(u)
        v = np.cross(n, u)
        circle = center + radius * (np.outer(np.cos(phi), u) + np.outer(np.sin(phi), v))
        e = cv2.fitEllipse(stereo.project(circle, "right").astype(np.float32))
        ratio = min(e[1]) / max(e[1]) - min(ell_r[1]) / max(ell_r[1])
        dang = np.deg2rad(
            (e[2] if e[1][0] >= e[1][1] else e[2] + 90)
            - (ell_r[2] if ell_r[1][0] >= ell_r[1][1] else ell_r[2] + 90)
        )
        err = ratio**2 + (np.sin(dang) * (1 - min(ell_r[1]) / max(ell_r[1]))) ** 2
        if err < best_err:
            best, best_err = n, err
    return BaselineResult(
        center_m=center, normal=best, radius_m=float(radius), time_s=time.perf_counter() - t0
    )
