"""Finding and identifying reference markers in one image.

1. Candidate dots: bright, filled, convex elliptical blobs (:mod:`.candidates`).
2. Sub-pixel edge points on rays across each candidate's rim (:mod:`.edges`); the dot must be
   ringed by the label's black all round (a bright blob on a bright surface is not a dot).
3. Identification: the code ring (:mod:`.ring_read`) or the adjacent AprilTag
   (:mod:`.tag_read`); a dot whose code cannot be read is dropped, and so is every dot of a
   code read twice in the image (one of them is misread).
4. The centre: with the camera model, the edge points are undistorted to ideal pixels and the
   ellipse is fitted there (the image of a circle is an ellipse only without distortion); the
   ideal centre is distorted back to report ``center_px``. The fit's covariance gives
   ``sigma_px``. The perspective bias (ellipse centre vs projected centre,
   :func:`measure.markers.bias.circle_center_bias_px`) is the caller's to remove: it needs
   the marker's pose.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Collection
from dataclasses import dataclass

import cv2
import numpy as np

from measure.image_input import to_gray
from measure.markers.candidates import DotCandidate, find_dot_candidates, to_8bit
from measure.markers.design import DEFAULT_DESIGN, MarkerDesign
from measure.markers.edges import bilinear, dot_edge_points
from measure.markers.ellipse import EllipseFit, fit_ellipse
from measure.markers.ring_read import read_ring, ring_samples
from measure.markers.tag_read import read_tag

_UNDISTORT = (cv2.TERM_CRITERIA_COUNT | cv2.TERM_CRITERIA_EPS, 50, 1e-12)
#: least white - black contrast of a dot (fraction of the image's full scale)
MIN_CONTRAST = 0.12
#: least fraction of a dot's rays that must give an edge point
MIN_EDGE_FRACTION = 0.6


@dataclass(frozen=True)
class MarkerDetection:
    """One identified marker.

    Attributes:
        code: the code number (0 .. ``design.n_codes()`` - 1).
        center_px: (2,) the dot's ellipse centre in the distorted image (pixel centres at
            integers); with a camera model the centre of the ellipse fitted in ideal pixels,
            distorted back.
        ellipse: ``((cx, cy), (major, minor), angle_deg)`` full axes, in ideal pixels (image
            pixels without a camera model).
        sigma_px: the fit's standard deviation of the centre per axis (px).
        cov_px: (2, 2) the centre's covariance (px², ideal pixels with a camera model).
        n_edge: edge points used; rms_px: their RMS distance from the ellipse.
        contrast: white - black (gray levels); confidence: the code read's margin (ring: the
            weakest sector's distance from the threshold as a fraction of the contrast; tag:
            1 - the tag's miss of the dot's centre in dot radii).
    """

    code: int
    center_px: np.ndarray
    ellipse: tuple
    sigma_px: float
    cov_px: np.ndarray
    n_edge: int
    rms_px: float
    contrast: float
    confidence: float


def _full_scale(gray: np.ndarray) -> float:
    return 255.0 if gray.dtype == np.uint8 else float(max(int(gray.max()), 1))


def _dark_surround(img: np.ndarray, dot: EllipseFit, white: float, black: float) -> bool:
    """The label's black gap around the dot (1.3 dot radii) is dark all round."""
    gap = ring_samples(img, dot, np.array([1.3]), 72)
    return bool(np.quantile(gap, 0.9) < black + 0.25 * (white - black))


def _dark_surround_candidate(img: np.ndarray, cand: DotCandidate) -> bool:
    """Quick test before the edges: darker at 1.3 radii all round than inside the blob."""
    t = np.linspace(0.0, 2 * np.pi, 36, endpoint=False)
    c, s = np.cos(cand.angle), np.sin(cand.angle)
    out, inn = [], []
    for rho, acc in ((1.3, out), (0.4, inn)):
        x, y = rho * cand.a * np.cos(t), rho * cand.b * np.sin(t)
        acc.append(bilinear(img, cand.center[0] + c * x - s * y, cand.center[1] + s * x + c * y))
    inside = float(np.median(inn[0]))
    return bool(np.quantile(out[0], 0.9) < 0.5 * inside + 0.5 * float(np.min(out[0])))


def _ideal_fit(
    pts: np.ndarray, K: np.ndarray, dist: np.ndarray
) -> tuple[EllipseFit, np.ndarray] | None:
    """The ellipse fitted to edge points undistorted to ideal pixels, and its centre
    distorted back to image pixels."""
    ideal = cv2.undistortPoints(pts.reshape(-1, 1, 2), K, dist, None, None, K, _UNDISTORT)
    ideal = ideal.reshape(-1, 2)
    fit = fit_ellipse(ideal)
    if fit is None:
        return None
    n = np.linalg.solve(K, np.array([fit.center[0], fit.center[1], 1.0]))
    back = cv2.projectPoints(n.reshape(1, 3), np.zeros(3), np.zeros(3), K, dist)[0].reshape(2)
    return fit, back


def _measure(
    img: np.ndarray,
    gray8: np.ndarray,
    cand: DotCandidate,
    full: float,
    K: np.ndarray | None,
    dist: np.ndarray,
    design: MarkerDesign,
) -> tuple[MarkerDetection, EllipseFit] | None:
    """The candidate's detection and its dot's ellipse in image pixels, or None."""
    if not _dark_surround_candidate(img, cand):
        return None
    pts, white, black = dot_edge_points(img, cand, MIN_CONTRAST * full)
    n_rays = int(np.clip(np.pi * (cand.a + cand.b) / 1.5, 48, 720))
    if len(pts) < max(16, MIN_EDGE_FRACTION * n_rays) or white - black < MIN_CONTRAST * full:
        return None
    raw = fit_ellipse(pts, refine=K is None)
    if raw is None or not (0.7 < raw.a / cand.a < 1.4) or raw.b < 0.5 * cand.b:
        return None
    if not _dark_surround(img, raw, white, black):
        return None
    if design.kind == "ring":
        code, conf = read_ring(img, raw, white, black, design)
    else:
        code, miss = read_tag(gray8, raw, design)
        conf = 1.0 - miss
    if code is None:
        return None
    fit, center = raw, raw.center.copy()
    if K is not None:
        ideal = _ideal_fit(pts, K, dist)
        if ideal is None:
            return None
        fit, center = ideal
    det = MarkerDetection(
        code=int(code),
        center_px=center,
        ellipse=fit.opencv(),
        sigma_px=float(np.sqrt(0.5 * np.trace(fit.cov_center))),
        cov_px=fit.cov_center,
        n_edge=fit.n,
        rms_px=fit.rms,
        contrast=float(white - black),
        confidence=float(conf),
    )
    return det, raw


def _in_label(center: np.ndarray, dots: list[EllipseFit], design: MarkerDesign) -> bool:
    """Whether ``center`` lies on the label of an identified ring marker (within its label
    radius, in units of its dot's ellipse): a white code sector there is not a dot."""
    reach = 2.0 * design.label_radius  # the label's radius in dot radii
    for dot in dots:
        c, s = np.cos(dot.angle), np.sin(dot.angle)
        dx, dy = center[0] - dot.center[0], center[1] - dot.center[1]
        u, v = (c * dx + s * dy) / dot.a, (-s * dx + c * dy) / dot.b
        if u * u + v * v < reach * reach:
            return True
    return False


def detect_markers(
    image: np.ndarray,
    K: np.ndarray | None = None,
    dist: np.ndarray | None = None,
    design: MarkerDesign = DEFAULT_DESIGN,
    codes: Collection[int] | None = None,
) -> list[MarkerDetection]:
    """Every identified marker in one image (uint8/uint16, gray or BGR).

    Args:
        image: the image (distorted, as the camera gives it).
        K, dist: the camera matrix and distortion (OpenCV model); with them the ellipse is
            fitted in ideal pixels. ``dist`` None with ``K``: no distortion.
        design: the marker design to look for.
        codes: if given, only these codes may be reported (others are dropped, never re-mapped).

    Returns:
        The detections, ordered by code. A hole (a dark bore in a bright plate) is never a
        candidate; a dot whose code cannot be read, or whose code is read twice, is dropped.
    """
    gray = np.ascontiguousarray(to_gray(image, "marker"))
    Km = None if K is None else np.asarray(K, dtype=np.float64).reshape(3, 3)
    d = np.zeros(5) if dist is None else np.asarray(dist, dtype=np.float64).ravel()
    gray8 = to_8bit(gray)
    full = _full_scale(gray)
    wanted = None if codes is None else {int(c) for c in codes}
    found, dots = [], []
    for cand in find_dot_candidates(gray8):  # largest first: a dot before its code's sectors
        if design.kind == "ring" and _in_label(cand.center, dots, design):
            continue
        out = _measure(gray, gray8, cand, full, Km, d, design)
        if out is None:
            continue
        det, raw = out
        dots.append(raw)
        if wanted is None or det.code in wanted:
            found.append(det)
    counts = Counter(m.code for m in found)
    return sorted((m for m in found if counts[m.code] == 1), key=lambda m: m.code)
