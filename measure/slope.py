"""Slope correction of gradient-maximum edge points: the bore wall's ramp inside the rim.

The gradient maximum of a blurred step lies on the step only where the image is flat on
both sides. Inside a tilted hole's rim it is not: the camera sees the bore wall just
inside its far rim, and the wall darkens with depth (the light reaches less of it); in
the image that is a ramp a few to a few tens of pixels wide, the narrower and steeper the
more steeply the wall is seen. Across the edge (x along the gradient direction, toward
the bright side) the gradient is then, to first order,

    I'(x) = A g(x) + s₊ Φ(x) + s₋ (1 − Φ(x)),

with g the Gaussian of the total blur σ, Φ its integral, A the step and s₊, s₋ the
slopes (gradient along the same direction) on the bright and the dark side. Setting
I''(x) = 0 gives the maximum at x* = (s₊ − s₋) σ² / A: it leans toward the side whose
slope has the step's sign. With A = √(2π) σ I'(0) and the slope read off the gradient
image 3σ from the point, less the step's own Gaussian tail there (I'(0) e^(−9/2), 1.1 %
of the peak, which would otherwise read as a slope and move every point outward by
0.004 σ), each point is moved back by x* along its gradient direction.

Only the *inside* slope is read (s₋ for a dark hole, s₊ for a lit background seen
through it); the outside one is taken as zero. Outside the rim is the part's surface,
flat over a few pixels (shading, vignetting and texture slopes are a hundredth of the
wall's), and what does lie there — a chamfer's or a lip's outer edge, a washer, a
grommet — is a second *edge*, not a slope: read 3σ away it would count its peak as a
slope and move the point by up to σ × its contrast ratio, where its real pull on the
maximum is some 30 times smaller.

Why it matters for the shape: the two cameras see the wall at different angles, so its
ramp is steeper in one image than in the other, the uncorrected shifts differ between
the images, enter the disparity and tilt the fitted circle (the realistic group's
⌀6 mm, 15° case: 0.21° without, 0.12° with the correction).

The shift varies slowly along the rim (it follows the wall's visibility and the light),
while a slope read 3σ away carries the noise and texture of single pixels, so it is
smoothed along the contour (running median over ``SMOOTH_POINTS`` points ordered by angle
about the region centroid) and limited to ``MAX_SHIFT_PX``: a larger value means another
edge within 3σ, where the first-order model does not hold, and the point is left alone.
"""

from __future__ import annotations

import cv2
import numpy as np

from measure.edge_kernels import periodic_median, slope_offsets, slope_queries

#: the inside slope is read this many blur σ from the edge point
SLOPE_OFFSET_SIGMA = 3.0
#: running median of the shift along the contour (points, about one per pixel of arc)
SMOOTH_POINTS = 15
#: shifts beyond this (px) are not first-order: such points are not moved
MAX_SHIFT_PX = 0.5


def _running_median(values: np.ndarray, angles: np.ndarray, window: int) -> np.ndarray:
    """Periodic running median of ``values`` ordered by ``angles`` (returned in input order)."""
    n = len(values)
    if window <= 1 or n <= window:
        return values
    order = np.argsort(angles)
    out = np.empty(n)
    out[order] = periodic_median(np.ascontiguousarray(values[order], np.float64), window)
    return out


def slope_shift(
    gx: np.ndarray,
    gy: np.ndarray,
    points_px: np.ndarray,
    normals: np.ndarray,
    peak: np.ndarray,
    sigma_px: float,
    center_px: tuple[float, float],
) -> np.ndarray:
    """Signed shift x* (px, along ``normals``) of each gradient-maximum edge point.

    Args:
        gx, gy: gradient images (float32, any common scale) in which the points lie.
        points_px: sub-pixel edge points (N, 2), pixel coordinates of ``gx``/``gy``.
        normals: unit gradient directions at the points (N, 2), toward the bright side.
        peak: gradient magnitude at the points (N,), the scale of ``gx``/``gy``.
        sigma_px: total blur of the edge (the Gaussian width of its gradient profile).
        center_px: the hole region's centroid (same coordinates), to order the points.

    Returns:
        x* per point, smoothed along the contour and set to 0 where it exceeds
        ``MAX_SHIFT_PX``; subtract ``x* × normal`` from the point.
    """
    n = len(points_px)
    if n == 0 or not np.isfinite(sigma_px) or sigma_px <= 0:
        return np.zeros(n)
    centre = np.asarray(center_px, dtype=np.float64)
    pts = np.ascontiguousarray(points_px, dtype=np.float64)
    nrm = np.ascontiguousarray(normals, dtype=np.float64)
    inward, qx, qy, angles = slope_queries(pts, nrm, centre, SLOPE_OFFSET_SIGMA * sigma_px)
    sx = cv2.remap(gx, qx, qy, cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE).ravel()
    sy = cv2.remap(gy, qx, qy, cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE).ravel()
    tail = np.exp(-0.5 * SLOPE_OFFSET_SIGMA**2)  # the step's own Gaussian tail
    peak = np.ascontiguousarray(peak, dtype=np.float64)
    x = slope_offsets(sx, sy, nrm, peak, inward, tail, float(sigma_px))
    x = _running_median(x, angles, SMOOTH_POINTS)
    return np.where(np.abs(x) <= MAX_SHIFT_PX, x, 0.0)
