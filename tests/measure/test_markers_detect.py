"""Render markers, detect them: codes right, centres within a stated bound of the truth, no
marker reported on a hole-only scene, the codes filter."""

from __future__ import annotations

import cv2
import numpy as np
import pytest
from markers_helpers import ring_of_markers, true_ideal_centre

from measure.errors import ImageError
from measure.markers import APRILTAG_DESIGN, RING_DESIGN, circle_center_bias_px, detect_markers
from measure.synth import RenderOptions, render_hole_pair
from measure.synth.markers import render_markers_pair

#: centre error bound (px, per axis) after the bias correction, default noise and blur
CENTRE_BOUND_PX = 0.05


@pytest.mark.parametrize("design", [RING_DESIGN, APRILTAG_DESIGN], ids=lambda d: d.kind)
def test_survey_view_markers_are_identified_and_centred(design):
    codes = [3, 250, 586] if design.kind == "apriltag" else [3, 250, 1220]
    st, _, _, ms = ring_of_markers(codes, tilt_deg=35.0, radius_m=0.035, design=design)
    r = render_markers_pair(st, ms, RenderOptions(blur_sigma_px=1.0), seed=1)
    for side, img in (("left", r.left), ("right", r.right)):
        K, d = (st.K_left, st.dist_left) if side == "left" else (st.K_right, st.dist_right)
        dets = detect_markers(img, K, d, design=design)
        assert [m.code for m in dets] == sorted(codes)
        for det in dets:
            m = next(x for x in ms if x.code == det.code)
            proj, C, N = true_ideal_centre(st, m, side)
            ideal = cv2.undistortPoints(det.center_px.reshape(1, 1, 2), K, d, P=K).ravel()
            np.testing.assert_allclose(ideal, det.ellipse[0], atol=1e-6)
            bias = circle_center_bias_px(K, C, N, 0.5 * m.diameter_m)
            assert np.abs(ideal - bias - proj).max() < CENTRE_BOUND_PX
            assert np.linalg.norm(bias) > 0.05  # the correction matters at this tilt
            assert 0 < det.sigma_px < 0.02


def test_codes_filter_drops_and_never_remaps():
    st, _, _, ms = ring_of_markers([10, 11, 12, 13], tilt_deg=10.0)
    img = render_markers_pair(st, ms, seed=2).left
    assert [m.code for m in detect_markers(img, st.K_left, st.dist_left)] == [10, 11, 12, 13]
    assert [m.code for m in detect_markers(img, codes={11, 13, 99})] == [11, 13]
    assert detect_markers(img, codes=()) == []


def test_no_marker_on_hole_scenes_and_markers_beside_a_hole():
    st, c, n, ms = ring_of_markers([5, 600, 900, 1100], tilt_deg=20.0)
    for opts in (
        RenderOptions(),
        RenderOptions(object_fraction=0.4, wall_light=0.5, chamfer_m=3e-4),
    ):
        bare = render_hole_pair(st, c, n, 0.008, opts, seed=4)
        assert detect_markers(bare.left) == [] and detect_markers(bare.right) == []
        with_m = render_hole_pair(st, c, n, 0.008, opts, seed=4, markers=ms)
        assert [m.code for m in detect_markers(with_m.right, st.K_right, st.dist_right)] == [
            5,
            600,
            900,
            1100,
        ]


def test_12_bit_colour_images():
    """A 12-bit Bayer camera's demosaiced BGR image (uint16) is read as gray."""
    st, _, _, ms = ring_of_markers([40, 41, 42], tilt_deg=25.0)
    r = render_markers_pair(st, ms, RenderOptions(bit_depth=12, bayer=True), seed=5)
    assert r.left.dtype == np.uint16 and r.left.ndim == 3
    dets = detect_markers(r.left, st.K_left, st.dist_left)
    assert [m.code for m in dets] == [40, 41, 42]


def test_bad_image_is_refused_with_a_clear_error():
    with pytest.raises(ImageError, match="uint8 or uint16"):
        detect_markers(np.zeros((20, 20), dtype=np.float32))
