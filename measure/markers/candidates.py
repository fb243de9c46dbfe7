"""Candidate dots: bright, filled, convex, elliptical blobs on a dark surround.

Searched on the image at half resolution (``INTER_AREA``): a pixel is bright when it exceeds
the mean of the ``BOX_PX`` square around it by ``OFFSET`` of full scale (so a dot is bright up
to about 300 px across in the full image, and the surface's texture and noise are not); the
outer boundaries of the bright components (OpenCV's two-level contours) are kept when they
are convex, fill their fitted ellipse and hold no dark hole. A hole's bore is dark: the bright
ring the threshold leaves around a bore has the bore as its hole and is refused here.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

#: half-resolution box (px) of the local mean and the offset above it (fraction of full scale)
BOX_PX = 151
OFFSET = 0.10
#: smallest minor axis of a dot in the full image (px)
MIN_MINOR_PX = 10.0
#: largest axis ratio (a dot seen at 75° is 3.9 : 1)
MAX_AXIS_RATIO = 4.0


@dataclass(frozen=True)
class DotCandidate:
    """A bright blob's ellipse in full-image pixels (``center`` (2,), semi-axes ``a >= b``,
    ``angle`` rad)."""

    center: np.ndarray
    a: float
    b: float
    angle: float


def to_8bit(gray: np.ndarray) -> np.ndarray:
    """An 8-bit copy of a uint8/uint16 gray image (uint16 scaled by its maximum)."""
    if gray.dtype == np.uint8:
        return gray
    top = max(int(gray.max()), 1)
    return cv2.convertScaleAbs(gray, alpha=255.0 / top)


def find_dot_candidates(gray8: np.ndarray) -> list[DotCandidate]:
    """Candidate dots in an 8-bit gray image, largest first."""
    h, w = gray8.shape
    small = cv2.resize(gray8, (w // 2, h // 2), interpolation=cv2.INTER_AREA)
    binary = cv2.adaptiveThreshold(
        small, 255, cv2.ADAPTIVE_THRESH_MEAN_C, cv2.THRESH_BINARY, BOX_PX, -OFFSET * 255.0
    )
    contours, hier = cv2.findContours(binary, cv2.RETR_CCOMP, cv2.CHAIN_APPROX_NONE)
    if hier is None:
        return []
    hier = hier[0]
    out = []
    min_half = 0.5 * MIN_MINOR_PX / 2.0
    for i, cnt in enumerate(contours):
        if hier[i][3] != -1 or len(cnt) < 12:
            continue  # a hole's boundary, or too small
        x, y, bw, bh = cv2.boundingRect(cnt)
        if x <= 1 or y <= 1 or x + bw >= small.shape[1] - 1 or y + bh >= small.shape[0] - 1:
            continue  # touches the border: may be cut
        area = cv2.contourArea(cnt)
        if area < np.pi * min_half**2:
            continue
        hole_area, child = 0.0, hier[i][2]
        while child != -1:
            hole_area += cv2.contourArea(contours[child])
            child = hier[child][0]
        if hole_area > 0.02 * area:
            continue
        hull = cv2.contourArea(cv2.convexHull(cnt))
        if hull <= 0 or area / hull < 0.93:
            continue
        (cx, cy), (d1, d2), ang = cv2.fitEllipse(cnt)
        a, b = 0.5 * max(d1, d2), 0.5 * min(d1, d2)
        if b < min_half or a / b > MAX_AXIS_RATIO:
            continue
        # the contour runs through the boundary pixels' centres: its area is short by ~half a
        # pixel of perimeter
        ell_area = np.pi * a * b
        if abs(area - ell_area) > 0.08 * ell_area + 2.0 * np.pi * np.sqrt(a * b) * 0.6:
            continue
        theta = np.radians(ang) + (0.0 if d1 >= d2 else np.pi / 2)
        out.append(
            DotCandidate(
                center=np.array([2.0 * cx + 0.5, 2.0 * cy + 0.5]),
                a=2.0 * a,
                b=2.0 * b,
                angle=float(theta),
            )
        )
    out.sort(key=lambda c: -c.a * c.b)
    return out
