"""measure_hole end to end on rendered pairs with known truth, and every bad input."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from measure_helpers import angle_deg, render, small_stereo

from measure import MeasureOptions, measure_hole
from measure.errors import (
    AmbiguousHoleError,
    CalibrationError,
    HoleAtBorderError,
    HoleNotFoundError,
    HoleSizeError,
    ImageError,
)
from measure.synth import RenderOptions


def _check(m, truth, radius_um=3.0, center_um=12.0, normal_deg=0.2):
    assert abs(m.radius_m - truth.edge_radius_m) < radius_um * 1e-6
    assert np.linalg.norm(m.center_m - truth.edge_center_m) < center_um * 1e-6
    assert angle_deg(m.normal, truth.normal) < normal_deg


@pytest.mark.parametrize(
    ("diameter", "tilt", "seed"), [(0.006, 0.0, 1), (0.010, 15.0, 2), (0.008, 30.0, 3)]
)
def test_accuracy_on_known_truth(diameter, tilt, seed):
    r = render(diameter, tilt, seed)
    m = measure_hole(r.left, r.right, small_stereo(), expected_diameter_m=diameter)
    _check(m, r.truth)
    assert m.status == "ok"
    assert m.normal @ m.center_m < 0  # toward the camera
    assert m.n_points > 300 and m.n_filled == 0
    assert m.rms_m < 10e-6
    sd = np.sqrt(np.diag(m.cov_center_radius))
    assert np.all(sd > 0) and np.all(sd < 5e-6)
    assert set(m.timings) == {"detect", "edges", "match", "fit"}
    # what a viewer draws: edge samples near the image ellipse, 3-D points near the circle
    (cx, cy), axes, _ = m.ellipse_left
    d = np.hypot(*(m.edges_left_px - (cx, cy)).T)
    assert np.all(np.abs(d - 0.25 * sum(axes)) < 0.1 * max(axes))
    assert m.points_m.shape[1] == 3 and m.inliers.sum() == m.n_points


def test_twelve_bit_images():
    r = render(0.008, 10.0, 4, RenderOptions(bit_depth=12, read_noise_dn=32.0))
    assert r.left.dtype == np.uint16 and r.left.max() > 255
    _check(measure_hole(r.left, r.right, small_stereo()), r.truth)


def test_occluded_edge_is_rejected_and_filled():
    r = render(0.008, 10.0, 3, RenderOptions(occlusion_fraction=0.25))
    m = measure_hole(r.left, r.right, small_stereo())
    _check(m, r.truth, radius_um=4.0, center_um=20.0, normal_deg=0.3)
    assert m.n_rejected + m.n_filled > 100
    assert m.status == "suspect"


def test_highlight_and_chamfer():
    r = render(0.008, 10.0, 5, RenderOptions(highlight=0.9))
    _check(measure_hole(r.left, r.right, small_stereo()), r.truth, 4.0, 20.0, 0.3)
    r = render(0.008, 10.0, 6, RenderOptions(chamfer_m=0.4e-3))
    m = measure_hole(r.left, r.right, small_stereo())
    _check(m, r.truth, 4.0, 20.0, 0.3)  # the bore edge, one chamfer below the surface


def test_published_options_run_and_are_worse_or_equal():
    r = render(0.008, 15.0, 7)
    best = measure_hole(r.left, r.right, small_stereo())
    pub = measure_hole(r.left, r.right, small_stereo(), options=MeasureOptions.published())
    assert pub.options.edge_method == "linear"
    assert abs(pub.radius_m - r.truth.radius_m) < 30e-6
    assert abs(best.radius_m - r.truth.radius_m) <= abs(pub.radius_m - r.truth.radius_m) + 1e-6


def test_roi_restricts_the_search():
    r = render(0.008, 0.0, 8)
    x, y, w, h = r.truth.window_left
    m = measure_hole(
        r.left, r.right, small_stereo(), roi=((x - 20, y - 20, w + 40, h + 40), (0, 0, 640, 512))
    )
    _check(m, r.truth)
    with pytest.raises(HoleNotFoundError):
        measure_hole(r.left, r.right, small_stereo(), roi=(0, 0, 100, 100))


# ------------------------------------------------------------------ bad input


def test_no_hole_in_view():
    r = render(0.008, 0.0, 9, offset=(0.05, 0.0, 0.0))  # 50 mm aside: out of the 34 mm view
    with pytest.raises(HoleNotFoundError, match="left image"):
        measure_hole(r.left, r.right, small_stereo())


def test_two_holes():
    a = render(0.008, 0.0, 10, offset=(-0.007, 0.0, 0.0))
    b = render(0.008, 0.0, 11, offset=(0.008, 0.0, 0.0))
    left, right = np.minimum(a.left, b.left), np.minimum(a.right, b.right)
    with pytest.raises(AmbiguousHoleError) as exc:
        measure_hole(left, right, small_stereo())
    assert len(exc.value.candidates) == 2
    # the expected size picks one when the two differ
    c = render(0.004, 0.0, 12, offset=(0.008, 0.0, 0.0))
    left, right = np.minimum(a.left, c.left), np.minimum(a.right, c.right)
    m = measure_hole(left, right, small_stereo(), expected_diameter_m=0.008)
    assert abs(m.diameter_m - 0.008) < 10e-6


def test_hole_cut_by_the_border():
    r = render(0.008, 0.0, 13, offset=(0.0, 0.0135, 0.0))
    with pytest.raises(HoleAtBorderError, match="border"):
        measure_hole(r.left, r.right, small_stereo())


@pytest.mark.parametrize(("value", "word"), [(255, "saturated"), (0, "black")])
def test_saturated_or_black(value, word):
    r = render(0.008, 0.0, 14)
    bad = np.full_like(r.left, value)
    with pytest.raises(ImageError, match=word):
        measure_hole(bad, r.right, small_stereo())


def test_sizes_and_types():
    r = render(0.008, 0.0, 15)
    with pytest.raises(ImageError, match="pair"):
        measure_hole(r.left, r.right[:, :600], small_stereo())
    with pytest.raises(ImageError, match="uint8 or uint16"):
        measure_hole(r.left.astype(np.float32), r.right.astype(np.float32), small_stereo())
    with pytest.raises(ImageError, match="single-channel"):
        measure_hole(r.left[None], r.right[None], small_stereo())
    # colour (BGR) is converted to luma; 8-bit data in uint16 is read as 8-bit
    gray = measure_hole(r.left, r.right, small_stereo())
    colour = measure_hole(np.dstack([r.left] * 3), np.dstack([r.right] * 3), small_stereo())
    wide = measure_hole(r.left.astype(np.uint16), r.right.astype(np.uint16), small_stereo())
    assert abs(colour.radius_m - gray.radius_m) < 1e-9
    assert abs(wide.radius_m - gray.radius_m) < 0.2e-6


def test_calibration_for_another_image_size():
    r = render(0.008, 0.0, 16)
    other = dataclasses.replace(small_stereo(), image_size=(648, 512))
    with pytest.raises(CalibrationError, match="648x512"):
        measure_hole(r.left, r.right, other)


def test_far_from_expected_diameter():
    r = render(0.008, 0.0, 17)
    with pytest.raises(HoleSizeError, match=r"expected 12\.000 mm"):
        measure_hole(r.left, r.right, small_stereo(), expected_diameter_m=0.012)
