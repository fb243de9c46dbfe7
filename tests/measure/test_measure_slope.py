"""Slope correction of gradient-maximum edge points (measure.slope) on 1-D profiles."""

from __future__ import annotations

import cv2
import numpy as np

from measure.slope import slope_shift

EDGE_X = 30.3  # the step, px
SIGMA = 0.9  # optics blur, px


def _image(inside_slope: float, outer_step_at: float | None = None) -> np.ndarray:
    """A vertical edge: the hole (x < EDGE_X) at 0.25 darkening away from the rim by
    ``inside_slope`` per px, the surface at 0.6 (optionally a second step up to 0.75 at
    ``outer_step_at``); blurred and area-sampled from a 20× finer grid."""
    k = 20
    x = (np.arange(64 * k) + 0.5) / k - 0.5  # pixel i is centred on x = i
    prof = np.where(x < EDGE_X, 0.25 + inside_slope * (x - EDGE_X), 0.6)
    if outer_step_at is not None:
        prof = np.where(x >= outer_step_at, 0.75, prof)
    fine = cv2.GaussianBlur(prof[None, :].astype(np.float32), (0, 0), SIGMA * k)[0]
    row = fine.reshape(64, k).mean(axis=1)
    return np.repeat(row[None, :], 40, axis=0).astype(np.float32)


def _peaks(img: np.ndarray):
    """Gradient images as measure.edges makes them, and the parabola peak per row."""
    smooth = cv2.GaussianBlur(img, (0, 0), 0.5)
    gx = cv2.Sobel(smooth, cv2.CV_32F, 1, 0, ksize=3)
    gy = cv2.Sobel(smooth, cv2.CV_32F, 0, 1, ksize=3)
    row = gx[20].astype(np.float64)
    i = int(np.argmax(row[10:50])) + 10
    off = 0.5 * (row[i - 1] - row[i + 1]) / (row[i - 1] - 2 * row[i] + row[i + 1])
    ys = np.arange(5.0, 35.0)
    pts = np.stack([np.full_like(ys, i + off), ys], axis=1)
    normals = np.tile([1.0, 0.0], (len(ys), 1))
    peak = np.full(len(ys), row[i])
    return gx, gy, pts, normals, peak


def _blur(gx: np.ndarray) -> float:
    """Total blur σ of the gradient profile (as measure.edges measures it)."""
    row = np.log(np.maximum(gx[20].astype(np.float64), 1e-12))
    i = int(np.argmax(gx[20]))
    return float(np.sqrt(-1.0 / (row[i - 1] - 2 * row[i] + row[i + 1])))


def test_the_inside_ramp_pull_is_undone():
    flat = _peaks(_image(0.0))[2][0, 0]  # the parabola step's own offset, without a ramp
    for slope in (0.01, 0.02, 0.04):  # gray level per px, against a step of 0.35
        gx, gy, pts, normals, peak = _peaks(_image(slope))
        shift = slope_shift(gx, gy, pts, normals, peak, _blur(gx), (-500.0, 20.0))
        before = pts[0, 0] - flat
        after = pts[0, 0] - shift[0] - flat
        assert before < -0.04  # the ramp pulls the maximum into the hole
        assert abs(after) < 0.25 * abs(before)
        assert np.allclose(shift, shift[0])


def test_a_flat_edge_is_left_alone():
    gx, gy, pts, normals, peak = _peaks(_image(0.0))
    shift = slope_shift(gx, gy, pts, normals, peak, _blur(gx), (-500.0, 20.0))
    assert np.abs(shift).max() < 0.01
    assert abs(pts[0, 0] - EDGE_X) < 0.05  # the parabola step itself: a few 0.01 px


def test_a_second_edge_outside_is_not_read_as_a_slope():
    # a chamfer's or washer's outer edge 3 px outside the rim: only the inside is read
    gx, gy, pts, normals, peak = _peaks(_image(0.0, outer_step_at=EDGE_X + 3.0))
    shift = slope_shift(gx, gy, pts, normals, peak, _blur(gx), (-500.0, 20.0))
    assert np.abs(shift).max() < 0.01
