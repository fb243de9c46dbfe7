"""The compiled loops of the measurement against the NumPy expressions they replace."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from measure.circle_kernels import rim_view_angles_max, solve_small
from measure.edge_kernels import parabola_points
from measure.edges import _edge_widths, gradient_kernels
from measure.nearside import rim_view_angles


def _reference_parabola(xs, ys, gx, gy, mag):
    """The array expressions of ``subpixel_edges`` before the compiled loop."""
    gxs, gys = gx[ys, xs], gy[ys, xs]
    horiz = np.abs(gxs) >= np.abs(gys)
    sx, sy = horiz.astype(np.intp), (~horiz).astype(np.intp)
    g0 = mag[ys, xs].astype(np.float64)
    gm = mag[ys - sy, xs - sx].astype(np.float64)
    gp = mag[ys + sy, xs + sx].astype(np.float64)
    den = gm - 2.0 * g0 + gp
    ok = (den < 0) & (g0 >= gm) & (g0 >= gp)
    with np.errstate(divide="ignore", invalid="ignore"):
        off = np.where(ok, 0.5 * (gm - gp) / den, 0.0)
    ok &= np.abs(off) <= 0.5
    pts = np.stack([xs + off * sx, ys + off * sy], axis=1)[ok].astype(np.float64)
    gxs, gys, strength = gxs[ok], gys[ok], g0[ok]
    widths = _edge_widths(gm[ok], strength, gp[ok], gxs, gys, horiz[ok])
    normals = np.stack([gxs, gys], axis=1) / np.maximum(strength, 1e-12)[:, None]
    return pts, strength, gxs, gys, widths, normals


def test_parabola_points_match_the_array_expressions():
    rng = np.random.default_rng(3)
    img = np.full((120, 140), 200, np.uint8)
    cv2.ellipse(img, ((70.3, 58.6), (80.0, 61.0), 17.0), 40, thickness=-1)
    img = cv2.GaussianBlur(img, (0, 0), 1.2)
    img = np.clip(img + rng.normal(0, 2.0, img.shape), 0, 255).astype(np.uint8)
    kd, ks = gradient_kernels(1.0, 255.0)
    gx = cv2.sepFilter2D(img, cv2.CV_32F, kd, ks)
    gy = cv2.sepFilter2D(img, cv2.CV_32F, ks, kd)
    mag = cv2.magnitude(gx, gy)
    ys, xs = np.nonzero(mag[1:-1, 1:-1] > 0.2 * mag.max())
    xs, ys = (xs + 1).astype(np.intp), (ys + 1).astype(np.intp)
    got = parabola_points(xs, ys, gx, gy, mag)
    want = _reference_parabola(xs, ys, gx, gy, mag)
    assert 100 < len(got[0]) < len(xs)  # some pixels are maxima, not all
    for g, w in zip(got, want, strict=True):
        assert g.shape == w.shape
        if g.dtype == np.float32:
            assert np.array_equal(g, w)
        else:
            np.testing.assert_allclose(g, w, rtol=1e-12, atol=1e-12)


def test_rim_view_angles_max_matches_the_array_expressions():
    rng = np.random.default_rng(5)
    center, normal = np.array([0.01, -0.02, 0.25]), np.array([0.2, 0.1, -1.0])
    normal /= np.linalg.norm(normal)
    pts = center + rng.normal(0.0, 0.005, (300, 3))
    cams = np.array([[0.0, 0.0, 0.0], [0.1, 0.0, 0.0], [0.05, 0.08, 0.02]])
    want = rim_view_angles(pts, center, normal, cams).max(axis=1)
    np.testing.assert_allclose(rim_view_angles_max(pts, center, normal, cams), want, atol=1e-13)


def test_small_solve_matches_lapack_and_reports_a_singular_matrix():
    rng = np.random.default_rng(9)
    for _ in range(20):
        a = rng.normal(size=(6, 6))
        M = a @ a.T + 0.1 * np.eye(6)  # as JᵀJ + λ D: symmetric positive definite
        b = rng.normal(size=6)
        x, ok = solve_small(M, b)
        assert ok
        np.testing.assert_allclose(x, np.linalg.solve(M, b), rtol=1e-9, atol=1e-12)
    x, ok = solve_small(np.zeros((6, 6)), np.ones(6))
    assert not ok
    with pytest.raises(np.linalg.LinAlgError):
        np.linalg.solve(np.zeros((6, 6)), np.ones(6))


def test_curvature_polar_matches_the_correction_and_the_polar_form():
    from measure.contour import curvature_correction
    from measure.edge_kernels import curvature_polar

    rng = np.random.default_rng(4)
    ell = ((310.2, 205.7), (180.0, 150.0), 23.0)
    t = np.deg2rad(ell[2])
    phi = rng.uniform(-np.pi, np.pi, 400)
    u, v = 90.0 * np.cos(phi), 75.0 * np.sin(phi)
    pts = np.stack(
        [310.2 + u * np.cos(t) - v * np.sin(t), 205.7 + u * np.sin(t) + v * np.cos(t)], 1
    )
    pts += rng.normal(0.0, 0.3, pts.shape)
    want = curvature_correction(pts, ell, 1.7)
    got, theta, r = curvature_polar(
        pts, 310.2, 205.7, 90.0, 75.0, np.cos(t), np.sin(t), 1.7, 311.0, 204.0
    )
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-11)
    d = want - (311.0, 204.0)
    np.testing.assert_allclose(theta, np.arctan2(d[:, 1], d[:, 0]), rtol=0, atol=1e-12)
    np.testing.assert_allclose(r, np.hypot(d[:, 0], d[:, 1]), rtol=1e-14)


def test_slope_kernels_match_the_array_expressions():
    from measure.edge_kernels import slope_offsets, slope_queries

    rng = np.random.default_rng(6)
    phi = rng.uniform(-np.pi, np.pi, 300)
    centre = np.array([50.0, 40.0])
    pts = centre + 30.0 * np.stack([np.cos(phi), np.sin(phi)], 1)
    nrm = (
        np.stack([np.cos(phi), np.sin(phi)], 1)
        * np.where(rng.random(300) < 0.7, 1.0, -1.0)[:, None]
    )
    inward, qx, qy, ang = slope_queries(pts, nrm, centre, 4.5)
    want_in = np.einsum("ij,ij->i", centre - pts, nrm) > 0
    side = np.where(want_in, 1.0, -1.0)
    q = pts + (side * 4.5)[:, None] * nrm
    assert np.array_equal(inward, want_in)
    assert np.array_equal(qx.ravel(), q[:, 0].astype(np.float32))
    assert np.array_equal(qy.ravel(), q[:, 1].astype(np.float32))
    np.testing.assert_allclose(ang, np.arctan2(pts[:, 1] - 40.0, pts[:, 0] - 50.0), atol=1e-12)
    sx, sy = rng.normal(0, 1, 300).astype(np.float32), rng.normal(0, 1, 300).astype(np.float32)
    peak = rng.uniform(0.5, 2.0, 300)
    peak[0] = 0.0  # not finite: 0
    s = sx * nrm[:, 0] + sy * nrm[:, 1] - peak * 0.0111
    with np.errstate(divide="ignore", invalid="ignore"):
        want = (
            (np.where(want_in, s, 0.0) - np.where(want_in, 0.0, s))
            * 1.3
            / (np.sqrt(2 * np.pi) * peak)
        )
    want = np.where(np.isfinite(want), want, 0.0)
    got = slope_offsets(sx, sy, nrm, peak, inward, 0.0111, 1.3)
    np.testing.assert_allclose(got, want, rtol=1e-14, atol=1e-15)


@pytest.mark.parametrize("window", [9, 15])
def test_periodic_median_is_scipys_wrapped_median_filter(window):
    from scipy.ndimage import median_filter

    from measure.edge_kernels import periodic_median

    rng = np.random.default_rng(window)
    for n in (window, window + 1, 613):
        v = np.round(rng.normal(0.0, 1.0, n), 1)  # with ties
        assert np.array_equal(
            periodic_median(v, window), median_filter(v, size=window, mode="wrap")
        )


def test_histogram_is_opencvs():
    from measure.image_kernels import histogram_u8

    rng = np.random.default_rng(8)
    for shape in ((512, 612), (7, 5), (1, 3)):
        img = rng.integers(0, 256, shape, dtype=np.uint8)
        img[0, 0] = 255
        want = cv2.calcHist([img], [0], None, [256], [0, 256]).ravel()
        assert np.array_equal(histogram_u8(img), want)


def test_scaled_int16_and_binary_moments_match_numpy_and_opencv():
    from measure.edge_kernels import binary_moments, scaled_int16

    rng = np.random.default_rng(12)
    gx = rng.normal(0.0, 1.0, (60, 70)).astype(np.float32)
    gy = rng.normal(0.0, 1.0, (60, 70)).astype(np.float32)
    scale = np.float32(16000.0 / np.abs(gx).max())
    dx, dy = scaled_int16(gx, gy, scale)
    assert np.array_equal(dx, (gx * scale).astype(np.int16))
    assert np.array_equal(dy, (gy * scale).astype(np.int16))
    mask = np.zeros((90, 120), np.uint8)
    cv2.ellipse(mask, ((60.4, 41.2), (70.0, 50.0), 33.0), 1, thickness=-1)
    window = mask[5:85, 7:113]  # a view, as the region's box
    m = cv2.moments(window, binaryImage=True)
    assert binary_moments(window) == (m["m00"], m["m10"], m["m01"])


def test_ring_histogram_is_calchist_under_the_ring_mask():
    from measure.edge_kernels import ring_histogram
    from measure.masks import ring_bounds, ring_mask

    rng = np.random.default_rng(13)
    region = np.zeros((150, 170), np.uint8)
    cv2.circle(region, (80, 70), 40, 1, -1)
    dist = cv2.distanceTransform(cv2.compare(region, 0, cv2.CMP_EQ), cv2.DIST_L2, 3)
    img = rng.integers(0, 256, region.shape, dtype=np.uint8)
    for inner, outer in ((3, 7), (0.05 * 80, 0.2 * 80), (2.865, 5.73)):  # bounds on the map's steps
        want = cv2.calcHist([img], [0], ring_mask(dist, inner, outer), [256], [0, 256]).ravel()
        assert np.array_equal(ring_histogram(img, dist, *ring_bounds(inner, outer)), want)


def test_off_sectors_matches_the_per_sector_medians():
    from measure.circle_kernels import off_sectors

    rng = np.random.default_rng(14)
    n = 500
    phi = rng.uniform(-np.pi, np.pi, n)
    h, dr = rng.normal(0, 1.0, n), rng.normal(0, 1.0, n)
    h[np.abs(phi) < 0.5] += 3.0  # some sectors off
    mask = rng.random(n) < 0.6
    k = np.floor((phi + np.pi) / np.deg2rad(10.0)).astype(np.int64)
    want = np.zeros(n, bool)
    for b in np.unique(k[mask]):
        sel = mask & (k == b)
        if sel.sum() >= 5 and np.hypot(np.median(h[sel]), np.median(dr[sel])) > 2.0:
            want |= sel
    got = off_sectors(h, dr, k, mask, 5, 2.0)
    assert want.any() and np.array_equal(got, want)


def test_searchsorted_is_numpys_even_on_unsorted_arrays():
    from measure.match_kernels import searchsorted_left

    rng = np.random.default_rng(15)
    for _ in range(50):
        arr = np.sort(rng.normal(0.0, 1.0, 40))
        arr[rng.integers(0, 40, 5)] = rng.normal(0.0, 1.0, 5)  # no longer sorted
        keys = rng.normal(0.0, 1.2, 60)
        keys[:20] = np.sort(keys[:20])
        assert np.array_equal(searchsorted_left(arr, keys), np.searchsorted(arr, keys))


def test_match_flank_is_the_array_expressions():
    from measure.match import _flanks, _steep
    from measure.match_kernels import match_flank

    rng = np.random.default_rng(16)
    t = np.linspace(-np.pi, np.pi, 400, endpoint=False)
    src = np.stack([300 + 80 * np.cos(t), 200 + 60 * np.sin(t)], 1) + rng.normal(0, 0.3, (400, 2))
    t2 = np.linspace(-np.pi, np.pi, 380, endpoint=False)
    dst = np.stack([250 + 78 * np.cos(t2), 200.4 + 61 * np.sin(t2)], 1)
    dst += rng.normal(0, 0.3, (380, 2))
    ws, wd = rng.uniform(0, 1, 400), rng.uniform(0, 1, 380)
    fs_, fd_ = rng.random(400) < 0.1, rng.random(380) < 0.1
    ss, sd = _steep(src, 0.34), _steep(dst, 0.34)
    for fs, fd in zip(_flanks(src), _flanks(dst), strict=True):
        x, y, w, f, i, ok = match_flank(src, fs, dst, fd, ss, sd, ws, wd, fs_, fd_)
        yd = dst[fd, 1]
        fd = fd[np.concatenate([[True], np.diff(yd) > 0])]
        yd, xd = dst[fd, 1], dst[fd, 0]
        ys = src[fs, 1]
        k = np.searchsorted(yd, ys)
        inside = (k > 0) & (k < len(yd))
        k = np.clip(k, 1, len(yd) - 1)
        lo, hi = fd[k - 1], fd[k]
        a = (ys - yd[k - 1]) / np.maximum(yd[k] - yd[k - 1], 1e-12)
        keep = inside & ss[fs] & sd[lo] & sd[hi]
        assert ok and keep.sum() > 100
        assert np.array_equal(x, (xd[k - 1] + a * (xd[k] - xd[k - 1]))[keep])
        assert np.array_equal(y, ys[keep]) and np.array_equal(i, fs[keep])
        assert np.array_equal(w, (ws[fs] * np.minimum(wd[lo], wd[hi]))[keep])
        assert np.array_equal(f, (fs_[fs] | fd_[lo] | fd_[hi])[keep])


def test_outline_prefilter_boxes_and_areas_are_opencvs():
    from measure.outline import outline_prefilter

    rng = np.random.default_rng(17)
    mask = (cv2.GaussianBlur(rng.random((200, 240)), (0, 0), 3.0) > 0.52).astype(np.uint8)
    cv2.circle(mask, (120, 100), 30, 1, -1)
    contours, _ = cv2.findContours(mask, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE)
    lengths = np.array([len(c) for c in contours])
    starts = np.concatenate([[0], np.cumsum(lengths)[:-1]])
    pts = np.concatenate(contours).reshape(-1, 2)
    for border_only in (False, True):
        ok, boxes, _ = outline_prefilter(pts, starts, mask.shape, 12.0, border_only)
        want = []
        for c in contours:
            x, y, w, h = cv2.boundingRect(c)
            b = x == 0 or y == 0 or x + w == 240 or y + h == 200
            a = cv2.contourArea(c)
            compact = b or not (
                a < 0.5 * w * h or min(w, h) < 0.3 * max(w, h) or 4 * np.pi * a < 0.45 * len(c) ** 2
            )
            want.append(w * h >= 12 and b == border_only and 12 <= a <= 0.5 * 200 * 240 and compact)
            assert tuple(boxes[len(want) - 1]) == (x, y, w, h)
        assert np.array_equal(ok, want) and 0 < ok.sum() < len(contours)
