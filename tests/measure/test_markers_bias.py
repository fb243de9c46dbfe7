"""The perspective bias of a circle's image centre, against a numeric check: the circle's rim
sampled, projected, and fitted by two ellipse fits (ours and OpenCV's direct fit)."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from measure.markers import circle_center_bias_many_px, circle_center_bias_px
from measure.markers.bias import circle_image_conic, conic_center
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


def test_closed_form_of_many_circles_matches_the_conic_route():
    """The batched closed form (pole of the line at infinity) against the image conic's centre
    ``A[:2, :2] c = -A[:2, 2]`` circle by circle, over random poses, sizes and normal signs."""
    rng = np.random.default_rng(7)
    C = np.column_stack([rng.uniform(-0.15, 0.15, (200, 2)), rng.uniform(0.15, 1.2, 200)])
    n = rng.normal(size=(200, 3))
    n[:, 2] = -np.abs(n[:, 2]) - 0.3  # facing the camera, up to about 75 deg of tilt
    n *= rng.choice([-1.0, 1.0], size=(200, 1)) * rng.uniform(0.5, 3.0, (200, 1))
    r = rng.uniform(0.001, 0.01, 200)
    many = circle_center_bias_many_px(K, C, n, r)
    for k in range(200):
        p = K @ C[k]
        conic = conic_center(circle_image_conic(K, C[k], n[k], r[k])) - p[:2] / p[2]
        np.testing.assert_allclose(many[k], conic, atol=1e-6)
    assert np.abs(many).max() > 0.1  # the draw has biases that matter
    with pytest.raises(ValueError, match="in front"):
        circle_center_bias_many_px(K, np.vstack([C[:2], [[0.0, 0.0, -0.1]]]), n[:3], r[:3])
