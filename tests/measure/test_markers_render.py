"""The marker renderer: exact-area pixels against brute-force point sampling of the same
pattern, hole scenes unchanged without markers, and markers where the camera model puts them."""

from __future__ import annotations

import numpy as np
import pytest
from markers_helpers import ring_of_markers

from measure.markers import APRILTAG_DESIGN, RING_DESIGN
from measure.markers.codes import apriltag_cells, ring_bits
from measure.synth import RenderOptions, render_hole_pair
from measure.synth.marker_draw import MARKER_BLACK, MARKER_WHITE, draw_markers, marker_axes


def _pattern(m, u, v):
    """Reflectance of marker ``m`` at marker coordinates (dot diameters); NaN off the label."""
    d = m.design
    r = np.hypot(u, v)
    white = r < 0.5
    if d.kind == "ring":
        on = r < d.label_radius
        bits = ring_bits(m.code, d.bits, d.min_distance)
        k = np.floor(np.mod(np.arctan2(v, u), 2 * np.pi) / (2 * np.pi / d.bits)).astype(int)
        white |= (r > d.ring_inner) & (r < d.ring_outer) & (bits[k % d.bits] == 1)
    else:
        x_lo, x_hi, y_lo, y_hi = d.label_box()
        on = (u > x_lo) & (u < x_hi) & (v > y_lo) & (v < y_hi)
        fld = np.ones((10, 10))
        fld[1:9, 1:9] = apriltag_cells(m.code)
        col = np.floor((u - (d.tag_offset - d.field_half)) / d.tag_cell).astype(int)
        row = np.floor((d.field_half - v) / d.tag_cell).astype(int)
        inside = (col >= 0) & (col < 10) & (row >= 0) & (row < 10)
        white |= inside & (fld[np.clip(row, 0, 9), np.clip(col, 0, 9)] == 1)
    out = np.where(white, MARKER_WHITE, MARKER_BLACK)
    return np.where(on, out, np.nan)


@pytest.mark.parametrize("design", [RING_DESIGN, APRILTAG_DESIGN], ids=lambda d: d.kind)
def test_pixels_are_the_area_integral_of_the_pattern(design):
    """Every pixel of a tilted marker against 12 × 12 point samples of the pattern per pixel
    (rays through the lens model, exactly undistorted): within the sampling's own error."""
    st, _, _, ms = ring_of_markers([77], tilt_deg=40.0, design=design)
    m = ms[0]
    img = np.zeros((st.image_size[1], st.image_size[0]), np.float32)
    (box,) = draw_markers(img, st, "left", [m], blur_sigma_px=0.0, vignetting_strength=0.0)
    x0, y0, w, h = box
    R = marker_axes(m.normal, m.up)
    C = np.asarray(m.center_m)
    s = 12
    offs = (np.arange(s) + 0.5) / s - 0.5
    rng = np.random.default_rng(0)
    patch = img[y0 : y0 + h, x0 : x0 + w]
    lo, hi = MARKER_BLACK + 0.02, MARKER_WHITE - 0.02
    ey, ex = np.nonzero((patch > lo) & (patch < hi))  # edge pixels: partly white
    pick = rng.choice(len(ey), 300, replace=False)
    ys = np.concatenate([ey[pick] + y0, rng.integers(y0, y0 + h, 100)])
    xs = np.concatenate([ex[pick] + x0, rng.integers(x0, x0 + w, 100)])
    px = (xs[:, None, None] + offs[None, :, None] + 0 * offs[None, None, :]).reshape(-1)
    py = (ys[:, None, None] + 0 * offs[None, :, None] + offs[None, None, :]).reshape(-1)
    ray = np.column_stack([st.normalized(np.column_stack([px, py]), "left"), np.ones(len(px))])
    depth = (R[:, 2] @ C) / (ray @ R[:, 2])
    P = ray * depth[:, None] - C
    u, v = (P @ R[:, 0]) / m.diameter_m, (P @ R[:, 1]) / m.diameter_m
    ref = _pattern(m, u, v).reshape(len(xs), s * s)
    keep = ~np.isnan(ref).any(axis=1)  # pixels wholly on the label
    ref_mean = ref[keep].mean(axis=1)
    got = img[ys[keep], xs[keep]]
    assert keep.sum() > 200
    # point sampling at 12 x 12 errs by up to ~1/24 of the contrast on an edge pixel (measured:
    # 0.033 worst, 0.003 mean, of a contrast of 0.84)
    assert np.abs(got - ref_mean).max() < 0.06
    assert np.abs(got - ref_mean).mean() < 0.005


def test_no_markers_leaves_the_hole_scene_unchanged_and_markers_only_add_labels():
    st, c, n, ms = ring_of_markers([1, 2], tilt_deg=15.0)
    opts = RenderOptions()
    base = render_hole_pair(st, c, n, 0.008, opts, seed=11)
    same = render_hole_pair(st, c, n, 0.008, opts, seed=11, markers=())
    assert np.array_equal(base.left, same.left) and np.array_equal(base.right, same.right)
    marked = render_hole_pair(st, c, n, 0.008, opts, seed=11, markers=ms)
    # the hole's window is untouched (its fresh noise comes first)
    x, y, w, h = base.truth.window_left
    assert np.array_equal(base.left[y : y + h, x : x + w], marked.left[y : y + h, x : x + w])
    assert not np.array_equal(base.left, marked.left)
