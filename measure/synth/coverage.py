"""Exact pixel-area coverage of straight edges (box-filtered steps), vectorised in float32.

A pixel is a unit square. A straight edge through the image at signed distance ``d`` (pixels,
positive: the pixel centre lies on the covered side) with unit normal ``(n_x, n_y)`` covers
the fraction ``P(n_x X + n_y Y < d)`` of the pixel, X and Y uniform on [-1/2, 1/2]: the CDF of
the sum of two uniforms of widths ``|n_x|`` and ``|n_y|`` (a trapezoid), piecewise linear and
quadratic. It equals the limit of infinitely many point samples per pixel for any edge of
curvature radius much larger than a pixel.
"""

from __future__ import annotations

import numpy as np

_TINY = np.float32(1e-6)


def edge_coverage(d_px: np.ndarray, gx: np.ndarray, gy: np.ndarray) -> np.ndarray:
    """Fraction (0..1, float32) of each pixel on the side ``f > 0`` of an edge ``f = 0``.

    Args:
        d_px: ``f / |grad f|`` at the pixel centre: signed distance to the edge (pixels).
        gx, gy: ``grad f`` in pixel coordinates (any scale; only its direction is used).
    """
    g = np.sqrt(gx * gx + gy * gy) + _TINY
    a, b = np.abs(gx) / g, np.abs(gy) / g
    hi, lo = np.maximum(a, b), np.maximum(np.minimum(a, b), _TINY)
    t = np.abs(d_px)
    q = np.clip(0.5 * (hi + lo) - t, 0.0, lo)
    # coverage of the far side's complement, for |d|: 1 - q²/(2 hi lo) - max(c2 - t, 0)/hi
    half = 1.0 - q * q / (2.0 * hi * lo) - np.maximum(0.5 * (hi - lo) - t, 0.0) / hi
    return np.where(d_px >= 0, half, 1.0 - half).astype(np.float32, copy=False)


def band_coverage(
    f: np.ndarray, lo: float, hi: float, gx: np.ndarray, gy: np.ndarray
) -> np.ndarray:
    """Fraction of each pixel where ``lo < f < hi`` (``f`` smooth, gradient ``(gx, gy)`` per
    pixel, the band much wider than a pixel)."""
    g = np.sqrt(gx * gx + gy * gy) + _TINY
    return edge_coverage((f - lo) / g, gx, gy) - edge_coverage((f - hi) / g, gx, gy)
