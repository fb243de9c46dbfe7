"""A through-hole against a lit background at a tilt: the rim, not the lit lens."""

from __future__ import annotations

import cv2
import numpy as np
from measure_helpers import angle_deg, render, small_stereo

from measure import measure_hole
from measure.detect import find_candidates
from measure.image_input import check_image
from measure.opening import with_wall_crescent
from measure.synth import RenderOptions

LIT = RenderOptions(bottom=0.95, hole_depth_m=0.004)


def test_lit_background_at_30_degrees_is_measured_at_the_rim():
    """At 30° of tilt the cameras see lenses about 25 % apart in size (the far wall's
    dark crescent takes a third of the opening); the rim is measured."""
    st = small_stereo()
    for seed in (0, 2):
        r = render(0.010, 30.0, seed, LIT)
        t = r.truth
        lens = []
        for img in (r.left, r.right):
            small = check_image(img, "left")[1]
            cand = find_candidates(small)[0]
            opening = with_wall_crescent(small, cand)
            assert cand.polarity == "bright"
            assert opening.diameter_px > 1.05 * cand.diameter_px  # the crescent joined
            lens.append(cand.diameter_px)
        m = measure_hole(r.left, r.right, st, expected_diameter_m=0.010)
        assert m.rim.polarity == "bright"
        assert abs(m.radius_m - t.edge_radius_m) < 5e-6
        assert np.linalg.norm(m.center_m - t.edge_center_m) < 15e-6
        assert angle_deg(m.normal, t.normal) < 0.2


def test_a_dark_hole_is_left_as_it_is():
    r = render(0.008, 10.0, 1)
    small = check_image(r.left, "left")[1]
    cand = find_candidates(small)[0]
    assert cand.polarity == "dark"
    assert with_wall_crescent(small, cand) == cand


def test_a_dark_blob_in_one_image_does_not_hide_a_lit_background():
    """Dark discs come before bright ones; a dark stain in one image only (no partner in
    the other) must not refuse the lit background's opening that both images show."""
    r = render(0.010, 15.0, 1, LIT)
    left = r.left.copy()
    cv2.circle(left, (60, 60), 20, 20, thickness=-1)  # a dark stain, left image only
    m = measure_hole(left, r.right, small_stereo(), expected_diameter_m=0.010)
    assert m.rim.polarity == "bright"
    assert abs(m.radius_m - r.truth.edge_radius_m) < 5e-6
