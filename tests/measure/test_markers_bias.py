"""The perspective bias of a circle's image centre, against a numeric check: the circle's rim
sampled, projected, and fitted by two ellipse fits (ours and OpenCV's direct fit)."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from measure.markers import circle_center_bias_px
from measure.markers.ellipse import fit_ellipse

K = np.array([[4640.0, 0.0, 1223.5], [0.0, 4640.0, 1023.5], [0.0, 0.0, 1.0]])


def _rim_projected(C, n, r, k=720):
    n = n / np.linalg.norm(n)
    a = np.cross(n, [0.3, 1.0, 0.2])
    a /= np.linalg.norm(a)
    b = np.cross(n, a)
    t = np.linspace(0, 2 * np.pi, k, endpoint=False)
    P = C + r * (np.outer(np.cos(t), a) + np.outer(np.sin(t), b))
    p = P @ K.T
    return p[:, :2] / p[:, 2:]


@pytest.mark.parametrize(
    "C, n, r",
    [
        ((0.01, -0.02, 0.25), (0.3, 0.2, -1.0), 0.0025),
        ((0.08, 0.05, 0.4), (-0.8, 0.1, -0.6), 0.005),
        ((-0.1, 0.07, 0.9), (0.5, -0.6, -0.5), 0.005),
        ((0.0, 0.0, 0.3), (0.0, 0.0, -1.0), 0.005),
    ],
)
def test_bias_matches_the_fitted_image_of_the_rim(C, n, r):
    C, n = np.array(C), np.array(n, dtype=float)
    bias = circle_center_bias_px(K, C, n, r)
    rim = _rim_projected(C, n, r)
    proj = (K @ C)[:2] / C[2]
    ours = fit_ellipse(rim)
    assert ours is not None
    np.testing.assert_allclose(ours.center - proj, bias, atol=2e-6)
    (cx, cy), _, _ = cv2.fitEllipseDirect(rim.astype(np.float32))
    np.testing.assert_allclose(np.array([cx, cy]) - proj, bias, atol=2e-3)
    # the sign of the normal does not matter; a fronto-parallel circle has no bias
    np.testing.assert_allclose(circle_center_bias_px(K, C, -n, r), bias, atol=1e-9)
    if abs(abs(n[2] / np.linalg.norm(n)) - 1.0) < 1e-12 and C[0] == 0 and C[1] == 0:
        np.testing.assert_allclose(bias, 0.0, atol=1e-9)


def test_bias_of_a_tilted_5mm_dot_is_a_tenth_of_a_pixel():
    """A 5 mm dot at 0.25 m tilted 45°, off-axis: the bias is well above the target precision."""
    n = np.array([np.sin(np.radians(45)), 0.0, -np.cos(np.radians(45))])
    b = circle_center_bias_px(K, np.array([0.03, 0.0, 0.25]), n, 0.0025)
    assert 0.05 < np.linalg.norm(b) < 0.5


def test_bias_refuses_a_circle_behind_the_camera():
    with pytest.raises(ValueError, match="in front"):
        circle_center_bias_px(K, np.array([0.0, 0.0, -0.2]), np.array([0, 0, 1.0]), 0.002)
