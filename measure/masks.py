"""Pixel masks of the hole region step (:mod:`measure.edges`), each one OpenCV pass:
thresholds of an 8-bit image, rings of a distance map, a box grown within an image."""

from __future__ import annotations

import cv2
import numpy as np


def _f32_above(x: float) -> np.float32:
    """The smallest float32 greater than ``x``."""
    f = np.float32(x)
    return f if float(f) > x else np.nextafter(f, np.float32(np.inf))


def _f32_at_most(x: float) -> np.float32:
    """The largest float32 not above ``x``."""
    f = np.float32(x)
    return f if float(f) <= x else np.nextafter(f, np.float32(-np.inf))


def ring_bounds(inner: float, outer: float) -> tuple[np.float32, np.float32]:
    """The float32 bounds [lo, hi] of the distances ``inner`` (exclusive) … ``outer``."""
    return _f32_above(inner), _f32_at_most(outer)


def ring_mask(outside_px: np.ndarray, inner: float, outer: float) -> np.ndarray:
    """Pixels between ``inner`` (exclusive) and ``outer`` px outside the region, from its
    float32 distance map, as a 0/255 ``uint8`` mask (one ``cv2.inRange`` pass)."""
    lo, hi = ring_bounds(inner, outer)
    return cv2.inRange(outside_px, float(lo), float(hi))


def below(img: np.ndarray, level: float) -> np.ndarray:
    """``img <= level`` as a 0/1 ``uint8`` mask (``cv2.threshold`` at ⌊level⌋ for 8-bit)."""
    if img.dtype == np.uint8:
        return cv2.threshold(img, float(np.floor(level)), 1, cv2.THRESH_BINARY_INV)[1]
    return (img <= level).view(np.uint8)


def above(img: np.ndarray, level: float) -> np.ndarray:
    """``img > level`` as a 0/1 ``uint8`` mask."""
    if img.dtype == np.uint8:
        return cv2.threshold(img, float(np.floor(level)), 1, cv2.THRESH_BINARY)[1]
    return (img > level).view(np.uint8)


def grow_box(
    box: tuple[int, int, int, int], pad: int, shape: tuple[int, int]
) -> tuple[slice, slice, int, int]:
    """Row and column slices of ``box`` grown by ``pad`` px (clipped), and their origin."""
    x, y, w, h = box
    x0, y0 = max(x - pad, 0), max(y - pad, 0)
    x1, y1 = min(x + w + pad, shape[1]), min(y + h + pad, shape[0])
    return slice(y0, y1), slice(x0, x1), x0, y0
