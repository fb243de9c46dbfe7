"""The renderers' fast paths (issue 27) give the images of the straightforward computation, bit
for bit: the plate and ring markers drawn in blocks against pixel by pixel, the plate rendered
and blurred over its box only against the whole frame, the compiled noise and quantisation
against NumPy and OpenCV, the rays computed band by band against all at once."""

from __future__ import annotations

import cv2
import numpy as np
import pytest
from measure_helpers import small_stereo

from measure import head_frame
from measure.markers.design import DEFAULT_DESIGN
from measure.synth import marker_draw, marker_pattern
from measure.synth.heads import toed_in_stereo
from measure.synth.marker_scenes import marker_grid_view
from measure.synth.pixel_rays import pixel_rays
from measure.synth.sensor import finish_region, quantize_u8
from measure.synth.target_pattern import _lit, _plate_pixel
from measure.synth.targets import (
    VIGNETTING,
    _plate_args,
    plate_region,
    render_plate,
    render_target_pair,
)
from measure.target import TargetSpec

BOARD = TargetSpec("chessboard", 9, 6, 0.009)


def _pose(shift=(0.0, 0.0, 0.0), tilt=(0.3, -0.2, 0.1), z=0.25) -> np.ndarray:
    P = np.eye(4)
    P[:3, :3] = cv2.Rodrigues(np.array(tilt))[0]
    c = BOARD.object_points()[:, :2].mean(axis=0)
    P[:3, 3] = np.array([*shift[:2], z + shift[2]]) - P[:3, :3] @ [*c, 0.0]
    return head_frame(small_stereo()) @ P


def _full_frame_pair(st, spec, T, blur, noise, seed):
    """The plate pair as rendered before issue 27: the whole frame drawn, blurred, noised."""
    rng = np.random.default_rng(seed)
    out = []
    Tr = np.eye(4)
    Tr[:3, :3], Tr[:3, 3] = st.R, st.T
    for side, M in (("left", T), ("right", Tr @ T)):
        img = render_plate(st, side, M[:3, :3], M[:3, 3], spec, VIGNETTING, 255.0)
        if blur > 0:
            img = cv2.GaussianBlur(img, (0, 0), blur)
        if noise > 0:
            cv2.setRNGSeed(int(rng.integers(0, 2**31 - 1)))
            dn = np.empty_like(img)
            cv2.randn(dn, 0.0, float(noise))
            img += dn
        np.maximum(img, 0.0, out=img)
        out.append(cv2.convertScaleAbs(img))
    return out


@pytest.mark.parametrize(
    ("shift", "blur", "noise"),
    [((0, 0, 0), 0.7, 2.0), ((0.03, 0.02, 0), 0.7, 2.0), ((0, 0, 0.1), 2.0, 0.0),
     ((-0.04, 0, 0), 0.0, 3.0)],
)  # fmt: skip
def test_plate_pair_is_the_whole_frame_render(shift, blur, noise):
    st = small_stereo()
    T = _pose(shift)
    new = render_target_pair(st, BOARD, T, blur, noise, seed=5)
    ref = _full_frame_pair(st, BOARD, T, blur, noise, seed=5)
    assert np.array_equal(new.left, ref[0]) and np.array_equal(new.right, ref[1])
    assert (new.left != new.left[0, 0]).mean() > 0.2  # the plate is in view


@pytest.mark.parametrize(
    "spec", [BOARD, TargetSpec("circles", 4, 7, 0.006)], ids=["board", "circles"]
)
def test_plate_blocks_are_the_per_pixel_values(spec):
    st = toed_in_stereo(image_size=(320, 256))
    T = _pose(tilt=(0.5, 0.3, 0.2), z=0.45)
    args = _plate_args(st, "left", T[:3, :3], T[:3, 3], spec, VIGNETTING, 255.0)
    nx, ny, box, H, kind, cols, rows, radius, bounds, light = args
    w, h = st.image_size
    img = np.empty((h, w), dtype=np.float32)
    plate_region(nx, ny, np.array([0, 0, w, h]), *args[2:], img)
    ref = np.empty_like(img)
    for yy in range(h):
        for xx in range(w):
            inside = box[0] <= xx < box[2] and box[1] <= yy < box[3]
            refl = (_plate_pixel(nx, ny, yy, xx, H, kind, cols, rows, radius, *bounds)
                    if inside else 0.25)  # fmt: skip
            ref[yy, xx] = refl * _lit(xx, yy, *light)
    assert np.array_equal(img, ref)
    assert len(np.unique(img)) > 100


def test_ring_blocks_are_the_per_pixel_values(monkeypatch):
    st = small_stereo()
    rng = np.random.default_rng(2)
    markers = marker_grid_view(st, rng, DEFAULT_DESIGN, 0.01, 0.22, 40.0, max_markers=4)
    drawn = {}
    for blocks in (True, False):
        patch = marker_pattern.marker_patch

        def draw(*a, blocks=blocks, patch=patch):
            patch(*a, blocks=blocks)

        monkeypatch.setattr(marker_draw, "marker_patch", draw)
        img = np.full((512, 640), 0.3, dtype=np.float32)
        boxes = marker_draw.draw_markers(img, st, "left", markers, 0.7, 0.25)
        drawn[blocks] = img
    assert boxes and min(min(b[2], b[3]) for b in boxes) >= marker_pattern.RING_BLOCKS_FROM_PX
    assert np.array_equal(drawn[True], drawn[False])


@pytest.mark.parametrize("full", [255, 4095])
@pytest.mark.parametrize("flipped", [False, True])
def test_compiled_camera_output_is_numpys(full, flipped):
    rng = np.random.default_rng(0)
    img = rng.uniform(-0.05, 1.1, (60, 80)).astype(np.float32)
    img[0, :4] = np.array([0.5, 1.5, 2.5, 254.5]) / full  # ties round to even
    bank = rng.standard_normal((70, 95), dtype=np.float32)
    fresh = rng.standard_normal((20, 30), dtype=np.float32)
    by0, bx0, (wx0, wy0) = 4, 9, (55, 50)  # the window runs past the image's corner
    view = bank[by0 : by0 + 60, bx0 : bx0 + 80]
    view = view[::-1] if flipped else view
    read = np.float32(2.0)
    dn = img * np.float32(full)
    dn += read * view
    dn[wy0:, wx0:] += read * (fresh[:10, :25] - view[wy0:, wx0:])
    np.maximum(dn, 0.0, out=dn)
    if full == 255:
        ref = cv2.convertScaleAbs(dn)
    else:
        ref = (np.minimum(dn, full) + np.float32(0.5)).astype(np.uint16)
    out = np.empty(img.shape, dtype=ref.dtype)
    finish_region(img, np.float32(full), read, bank, by0, bx0, flipped, fresh, wx0, wy0, full, out)
    assert np.array_equal(out, ref)
    q = np.empty((60, 80), dtype=np.uint8)
    noise = rng.standard_normal((60, 80), dtype=np.float32)
    quantize_u8(dn[10:30, 5:45] / 4, noise, 5, 10, q)
    want = np.maximum(dn[10:30, 5:45] / 4 + noise[10:30, 5:45], 0.0)
    assert np.array_equal(q[10:30, 5:45], cv2.convertScaleAbs(want))


def test_rays_by_band_are_the_exact_rays():
    st = toed_in_stereo(image_size=(300, 200))
    nx, ny = pixel_rays(st, "left", rows=(130, 140))
    pts = np.array([[0.0, 130.0], [299.0, 139.0], [17.0, 135.0]])
    exact = st.normalized(pts, "left").astype(np.float32)
    got = np.stack([nx[pts[:, 1].astype(int), pts[:, 0].astype(int)],
                    ny[pts[:, 1].astype(int), pts[:, 0].astype(int)]], axis=1)  # fmt: skip
    assert np.array_equal(got, exact)
    full = pixel_rays(st, "left")
    assert full[0] is nx and not nx.flags.writeable
    vv, uu = np.mgrid[0:200, 0:300].astype(np.float64)
    all_at_once = st.normalized(np.stack([uu.ravel(), vv.ravel()], axis=1), "left")
    assert np.array_equal(nx.ravel(), all_at_once[:, 0].astype(np.float32))
