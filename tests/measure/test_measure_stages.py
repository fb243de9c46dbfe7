"""Each stage on known truth: renderer, sub-pixel edges, contour, matching, triangulation, fit."""

from __future__ import annotations

import cv2
import numpy as np
import pytest
from measure_helpers import render, small_stereo

from measure import fit_circle_3d
from measure.circle import orthogonal_distance
from measure.contour import build_contour, ellipse_distance
from measure.detect import check_image, find_candidates
from measure.edges import hole_region, subpixel_edges
from measure.errors import FitError
from measure.match import match_contours
from measure.synth import RenderOptions, render_reference_pair
from measure.triangulate import (
    optimal_correction,
    rectified_fundamental,
    triangulate,
    triangulate_dlt,
)


def _truth_ellipse_px(stereo, truth, side: str, n: int = 720) -> np.ndarray:
    ref = np.array([1.0, 0.0, 0.0])
    u = np.cross(truth.normal, ref)
    u /= np.linalg.norm(u)
    v = np.cross(truth.normal, u)
    phi = np.linspace(0, 2 * np.pi, n, endpoint=False)
    pts = truth.edge_center_m + truth.edge_radius_m * (
        np.outer(np.cos(phi), u) + np.outer(np.sin(phi), v)
    )
    return stereo.project(pts, side)


def test_renderer_is_seeded_and_has_the_requested_format():
    a = render(0.008, 10.0, 3)
    b = render(0.008, 10.0, 3)
    c = render(0.008, 10.0, 4)
    assert np.array_equal(a.left, b.left) and not np.array_equal(a.left, c.left)
    assert a.left.dtype == np.uint8 and a.left.shape == (512, 640)
    d = render(0.008, 10.0, 3, RenderOptions(bit_depth=12, read_noise_dn=32))
    assert d.left.dtype == np.uint16 and 1000 < int(np.median(d.left)) < 4095
    x, y, w, h = a.truth.window_left
    assert a.left[y + h // 2, x + w // 2] < 40  # dark bore at the window centre
    assert np.median(a.left) > 100  # bright surface around


@pytest.mark.parametrize("method", ["parabola", "linear"])
def test_subpixel_edges_lie_on_the_projected_truth(method):
    r = render(0.008, 20.0, 5)
    st = small_stereo()
    full, small = check_image(r.left, "left")
    (cand,) = find_candidates(small)
    region = hole_region(r.left, full, cand)
    edges = subpixel_edges(r.left, full, region, method, 0.5)
    truth_ell = cv2.fitEllipse(_truth_ellipse_px(st, r.truth, "left").astype(np.float32))
    d = np.abs(ellipse_distance(edges.points_px, truth_ell))
    assert len(edges.points_px) > 300
    assert np.median(d) < 0.12 and np.percentile(d, 95) < 0.35
    assert 0.8 < edges.blur_sigma_px < 2.0  # optics 0.7 px + smoothing + Sobel


def test_contour_fills_gaps_and_reports_them():
    rng = np.random.default_rng(0)
    phi = np.sort(rng.uniform(0, 2 * np.pi, 900))
    pts = np.stack([300 + 80 * np.cos(phi), 200 + 60 * np.sin(phi)], axis=1)
    keep = ~((phi > 1.0) & (phi < 1.6))  # a broken edge
    c = build_contour(pts[keep], (300.0, 200.0))
    assert c.filled.sum() > 20 and c.long_gap.sum() > 0
    assert np.abs(ellipse_distance(c.points_px, c.ellipse)).max() < 0.05
    assert abs(c.ellipse[0][0] - 300) < 0.01 and abs(max(c.ellipse[1]) - 160) < 0.02


def test_contour_sheds_a_false_arc():
    phi = np.linspace(-np.pi, np.pi, 1000, endpoint=False)
    r = np.where((phi > 0.3) & (phi < 0.9), 62.0, 70.0)  # a reflection cutting the rim
    pts = np.stack([200 + r * np.cos(phi), 150 + r * np.sin(phi)], axis=1)
    c = build_contour(pts, (200.0, 150.0))
    assert c.n_outliers > 50
    assert max(c.ellipse[1]) == pytest.approx(140.0, abs=0.05)


def test_optimal_correction_matches_opencv_and_triangulation_matches_dlt():
    st = small_stereo()
    rng = np.random.default_rng(1)
    xl = rng.uniform(100, 500, (20, 2))
    xr = xl + np.array([-60.0, 0.0]) + rng.normal(0, 0.3, (20, 2))
    a, b = optimal_correction(xl, xr)
    ca, cb = cv2.correctMatches(
        rectified_fundamental(st), xl.reshape(1, -1, 2), xr.reshape(1, -1, 2)
    )
    np.testing.assert_allclose(a, ca.reshape(-1, 2), atol=1e-6)
    np.testing.assert_allclose(b, cb.reshape(-1, 2), atol=1e-6)
    np.testing.assert_allclose(triangulate(st, a, b), triangulate_dlt(st, a, b), atol=1e-12)


def test_matching_and_triangulation_recover_a_known_circle():
    st = small_stereo()
    r = render(0.008, 25.0, 6)
    ptsl = _truth_ellipse_px(st, r.truth, "left", 800)
    ptsr = _truth_ellipse_px(st, r.truth, "right", 800)
    rl, rr = st.undistort_rectify(ptsl, "left"), st.undistort_rectify(ptsr, "right")
    ones, no = np.ones(800), np.zeros(800, bool)
    m = match_contours(rl, ones, no, rr, ones, no)
    X = triangulate(st, m.left_rect, m.right_rect)
    t = r.truth
    assert len(X) > 900
    assert orthogonal_distance(X, t.edge_center_m, t.normal, t.edge_radius_m).max() < 0.3e-6
    np.testing.assert_allclose(m.left_rect[:, 1], m.right_rect[:, 1])


def _circle_points(n, noise, rng, c=(0.01, -0.02, 0.25), nrm=(0.2, -0.1, -1.0), r=0.005):
    nrm = np.array(nrm) / np.linalg.norm(nrm)
    u = np.cross(nrm, [1.0, 0, 0])
    u /= np.linalg.norm(u)
    v = np.cross(nrm, u)
    phi = rng.uniform(0, 2 * np.pi, n)
    p = np.array(c) + r * (np.outer(np.cos(phi), u) + np.outer(np.sin(phi), v))
    return p + rng.normal(0, noise, p.shape), np.array(c), nrm, r, phi


def test_circle_fit_on_known_truth_with_covariance():
    rng = np.random.default_rng(2)
    errs, sds = [], []
    for _ in range(40):
        p, c, n, r, _ = _circle_points(400, 5e-6, rng)
        f = fit_circle_3d(p)
        errs.append(f.radius - r)
        sds.append(np.sqrt(f.cov_center_radius[3, 3]))
        assert np.linalg.norm(f.center - c) < 3e-6
        assert f.normal @ n > np.cos(np.radians(0.1))  # oriented toward the origin (camera)
    assert abs(np.mean(errs)) < 0.5e-6
    assert np.std(errs) == pytest.approx(np.mean(sds), rel=0.35)  # the covariance is honest


def test_circle_fit_rejects_outliers_and_uses_weights():
    rng = np.random.default_rng(3)
    p, c, _n, r, phi = _circle_points(600, 3e-6, rng)
    bad = (phi > 1.0) & (phi < 2.5)  # 24 % of the rim: a burr 0.5 mm inside
    p[bad] = c + (p[bad] - c) * 0.9
    f = fit_circle_3d(p)
    assert abs(f.radius - r) < 1e-6 and np.linalg.norm(f.center - c) < 2e-6
    assert f.n_rejected >= bad.sum() * 0.95 and not f.inliers[bad].any()
    w = np.where(bad, 0.0, 1.0)
    g = fit_circle_3d(p, w, robust=False)
    assert abs(g.radius - r) < 1e-6 and g.n_used == (~bad).sum()
    pub = fit_circle_3d(p[~bad], cost="published")
    assert abs(pub.radius - r) < 5e-6
    with pytest.raises(FitError):
        fit_circle_3d(p[:5])


def test_reference_target_renders_and_measures():
    from measure import measure_hole
    from measure.synth import hole_in_view

    st = small_stereo()
    c, n = hole_in_view(st, 0.1, 0.3)
    r = render_reference_pair(st, c, n, 0.010, seed=2)
    m = measure_hole(r.left, r.right, st, expected_diameter_m=0.010)
    assert abs(m.radius_m - 0.005) < 3e-6 and np.linalg.norm(m.center_m - c) < 10e-6


def test_circle_lm_reaches_the_minimum_scipy_finds():
    """The hand-written LM of the orthogonal cost against scipy's MINPACK LM on the same
    residuals (numerical Jacobian), from the same rough start."""
    from scipy.optimize import least_squares

    from measure.circle import _basis, _residuals, _unpack, initial_circle

    rng = np.random.default_rng(7)
    for noise, arc in ((1e-6, 2 * np.pi), (20e-6, 2 * np.pi), (3e-6, 2.1)):
        p, *_, phi = _circle_points(600, noise, rng)
        p = p[phi < arc]  # a third of the rim: the rough start is far off
        w = rng.uniform(0.5, 1.0, len(p))
        ours = fit_circle_3d(p, w, robust=False)
        c0, n0, r0 = initial_circle(p, w)
        u, v = _basis(n0)
        x0 = np.concatenate([c0 * 1e3, [0.0, 0.0, r0 * 1e3]])
        args = (p * 1e3, np.sqrt(w), n0, u, v, "orthogonal")
        sol = least_squares(_residuals, x0, args=args, method="lm", xtol=1e-14, ftol=1e-14)
        cs, ns, rs = _unpack(sol.x, n0, u, v)
        assert np.linalg.norm(ours.center - cs / 1e3) < 1e-9
        assert abs(ours.radius - rs / 1e3) < 1e-9
        assert abs(ours.normal @ ns) > np.cos(1e-6)
        mine = orthogonal_distance(p, ours.center, ours.normal, ours.radius)
        theirs = orthogonal_distance(p, cs / 1e3, ns, rs / 1e3)
        assert np.sum(w * mine**2) <= np.sum(w * theirs**2) * (1 + 1e-9)


def test_circle_kernels_match_the_array_expressions():
    from measure.circle import _basis
    from measure.circle_kernels import orthogonal_system

    rng = np.random.default_rng(11)
    p, c, n, r, _ = _circle_points(200, 30e-6, rng)
    p, c, r = p * 1e3, c * 1e3 + 0.01, r * 1e3 * 1.001  # mm, a little off the optimum
    sw = np.sqrt(rng.uniform(0.2, 1.0, len(p)))
    u, v = _basis(n)
    A, g, ee = orthogonal_system(p, sw, c, n, u, v, r)
    d = p - c
    h = d @ n
    q = d - np.outer(h, n)
    rho = np.linalg.norm(q, axis=1)
    e = np.concatenate([h * sw, (rho - r) * sw])
    Jh = np.column_stack([np.tile(-n, (len(p), 1)), d @ u, d @ v, np.zeros(len(p))])
    Jr = np.column_stack([-q / rho[:, None], -(h / rho) * (d @ u), -(h / rho) * (d @ v),
                          -np.ones(len(p))])  # fmt: skip
    J = np.vstack([Jh * sw[:, None], Jr * sw[:, None]])
    np.testing.assert_allclose(A, J.T @ J, rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(g, J.T @ e, rtol=1e-10, atol=1e-12)
    assert ee == pytest.approx(e @ e, rel=1e-12)
    np.testing.assert_allclose(
        orthogonal_distance(p, c, n, r), np.hypot(h, rho - r), rtol=1e-12, atol=1e-12
    )
