"""The near-side check: rim view angles and dropping a sector a camera sees over a chamfer."""

from __future__ import annotations

import numpy as np
import pytest
from measure_helpers import angle_deg, render, small_stereo

from measure import MeasureOptions, fit_circle_3d, measure_hole
from measure.nearside import fit_with_near_side_check, rim_view_angles
from measure.synth import RenderOptions

CENTER = np.array([0.0, 0.0, 0.25])
NORMAL = np.array([0.0, 0.0, -1.0])  # toward the cameras at z = 0
RADIUS = 0.005


def _circle_points(n: int = 600) -> tuple[np.ndarray, np.ndarray]:
    phi = np.linspace(-np.pi, np.pi, n, endpoint=False)
    pts = CENTER + RADIUS * np.stack([np.cos(phi), np.sin(phi), np.zeros(n)], axis=1)
    return pts, phi


def test_rim_view_angles_on_axis_near_and_far_side():
    pts = CENTER + np.array([[RADIUS, 0.0, 0.0], [-RADIUS, 0.0, 0.0], [0.0, RADIUS, 0.0]])
    on_axis = CENTER + 0.25 * NORMAL + np.array([RADIUS, 0.0, 0.0])  # straight above pts[0]
    off = CENTER + 0.1 * NORMAL + np.array([0.1 + RADIUS, 0.0, 0.0])  # 45° past pts[0]
    ang = np.rad2deg(rim_view_angles(pts, CENTER, NORMAL, np.stack([on_axis, off])))
    assert ang[0, 0] == pytest.approx(0.0, abs=1e-9)
    assert ang[0, 1] == pytest.approx(45.0, abs=1e-9)  # near side: looks over the rim
    assert ang[1, 1] < -40.0  # far side of the hole for that camera
    # a point a quarter turn round: the camera is only the radius beyond it, 0.1 m up
    assert ang[2, 1] == pytest.approx(np.rad2deg(np.arctan2(-RADIUS, 0.1)), abs=1e-9)


def _scene(displace_m: float, seed: int = 0):
    """A circle seen by a camera on the axis and one 41° off it, toward azimuth 0; the
    sector that camera sees over the rim (±50°) pushed ``displace_m`` deeper."""
    rng = np.random.default_rng(seed)
    pts, phi = _circle_points()
    pts = pts + rng.normal(0.0, 3e-6, pts.shape)
    sector = np.abs(phi) < np.deg2rad(50)
    pts[sector] -= displace_m * NORMAL
    t = np.deg2rad(41.0)
    cams = np.stack(
        [CENTER + 0.25 * NORMAL, CENTER + 0.25 * (np.cos(t) * NORMAL + [np.sin(t), 0, 0])]
    )
    return pts, cams, sector


def test_near_side_sector_off_the_circle_is_dropped():
    pts, cams, sector = _scene(60e-6)
    circ, n_drop = fit_with_near_side_check(pts, np.ones(len(pts)), cams, 25.0)
    assert n_drop >= 0.8 * sector.sum()
    assert not circ.inliers[sector].any() or circ.inliers[sector].mean() < 0.2
    assert circ.n_rejected >= n_drop
    assert abs(circ.radius - RADIUS) < 1e-6
    assert np.linalg.norm(circ.center - CENTER) < 2e-6
    assert angle_deg(circ.normal, NORMAL) < 0.02


def test_consistent_near_side_points_are_all_kept():
    pts, cams, _ = _scene(0.0)
    circ, n_drop = fit_with_near_side_check(pts, np.ones(len(pts)), cams, 25.0)
    plain = fit_circle_3d(pts)
    assert n_drop == 0
    assert circ.n_used == plain.n_used
    assert circ.radius == pytest.approx(plain.radius, abs=1e-12)


def test_steep_chamfer_view_is_measured_at_the_bore_edge():
    """A 0.5 mm chamfer tilted 30°: one camera looks past it at about 41°.

    In this scene the plain robust fit keeps that camera's near-side sector (radius about
    11 µm short, normal 0.5° off); with the check the bore edge is measured.
    """
    r = render(0.010, 30.0, 2, RenderOptions(chamfer_m=0.5e-3))
    t = r.truth
    m = measure_hole(r.left, r.right, small_stereo(), expected_diameter_m=0.010)
    off = measure_hole(
        r.left, r.right, small_stereo(), options=MeasureOptions(near_side_max_angle_deg=None)
    )
    err = abs(m.radius_m - t.edge_radius_m)
    assert err < 3e-6
    assert angle_deg(m.normal, t.normal) < 0.15
    assert np.linalg.norm(m.center_m - t.edge_center_m) < 10e-6
    assert abs(off.radius_m - t.edge_radius_m) > 2 * err
    assert m.n_rejected > off.n_rejected


def test_fit_from_a_start_skips_the_robust_start_and_rejects():
    rng = np.random.default_rng(3)
    pts, _ = _circle_points(400)
    pts = pts + rng.normal(0.0, 2e-6, pts.shape)
    pts[:40] += 80e-6 * NORMAL  # a false arc, 10 % of the points
    plain = fit_circle_3d(pts)
    again = fit_circle_3d(pts, start=plain)
    assert again.radius == pytest.approx(plain.radius, abs=1e-9)
    assert angle_deg(again.normal, plain.normal) < 1e-3
    assert not again.inliers[:40].any()
    one = fit_circle_3d(pts[40:], start=plain, robust=False)
    assert one.n_rejected == 0 and one.n_used == 360
    assert abs(one.radius - RADIUS) < 1e-6
