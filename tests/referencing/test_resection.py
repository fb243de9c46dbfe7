"""Locating a stop against the surveyed markers: the pose, a moved marker refused by id, the
fall-back with too few markers."""

from __future__ import annotations

import numpy as np
import pytest

from cell.referencing import resect
from cell.referencing.layout import stop_pose
from cell.referencing.synthetic import observe
from robots.transforms import so3_exp


@pytest.fixture(scope="module")
def network(marker_truth):
    """The markers as a perfect survey would give them (the truth), with a 5 um covariance."""
    n = len(marker_truth.ids)
    return marker_truth.ids, marker_truth.true, np.eye(3 * n) * (5e-6) ** 2


def _stop(small_cell, stereo, marker_truth, hole="PVL", seed=0):
    T = stop_pose(small_cell, stereo, hole)
    prior = T.copy()
    prior[:3, :3] = so3_exp(np.radians([0.02, -0.01, 0.03])) @ T[:3, :3]
    prior[:3, 3] += [3e-4, -2e-4, 1e-4]  # the arm's idea of the pose
    return T, observe(marker_truth, stereo, T, hole, 0.05, np.random.default_rng(seed), prior)


def test_a_stop_is_located_to_micrometres(small_cell, stereo, marker_truth, network):
    T, view = _stop(small_cell, stereo, marker_truth)
    r = resect(view, stereo, *network, 0.05)
    assert r.ok and len(r.used) >= 4 and not r.refused
    c_left = np.array([0.0, 0.0, 0.25])
    p, cov = r.point(c_left)
    true = T[:3, :3] @ c_left + T[:3, 3]
    assert np.linalg.norm(p - true) < 15e-6
    assert np.linalg.norm(p - true) < 4 * np.sqrt(np.trace(cov))


def test_a_marker_moved_after_the_survey_is_caught_by_id(small_cell, stereo, marker_truth,
                                                        network):  # fmt: skip
    ids, P, C = network
    T, view = _stop(small_cell, stereo, marker_truth)
    moved = view.both()[0]
    P_survey = P.copy()
    P_survey[ids.index(moved)] += [0.0, 4e-4, 0.0]  # knocked 0.4 mm since the survey
    r = resect(view, stereo, ids, P_survey, C, 0.05)
    assert r.ok and moved in r.refused and moved not in r.used
    assert "moved since the survey" in r.refused[moved]
    p, _ = r.point(np.array([0.0, 0.0, 0.25]))
    assert np.linalg.norm(p - (T[:3, :3] @ [0.0, 0.0, 0.25] + T[:3, 3])) < 20e-6


def test_a_stop_with_three_markers_falls_back(small_cell, stereo, marker_truth, network):
    _T, view = _stop(small_cell, stereo, marker_truth)
    keep = view.both()[:3]
    for d in (view.uv_left, view.uv_right):
        for m in list(d):
            if m not in keep:
                d.pop(m)
    r = resect(view, stereo, *network, 0.05)
    assert not r.ok and "3 usable markers, 4 needed" in r.reason
    assert np.array_equal(r.T_cell_left, view.T_cell_left_prior)


def test_the_marker_jacobian_matches_finite_differences(small_cell, stereo, marker_truth):
    from cell.referencing import resection as rs

    _T, view = _stop(small_cell, stereo, marker_truth)
    obs = rs._Obs(view, stereo, {m: k for k, m in enumerate(marker_truth.ids)})
    K = (np.asarray(stereo.K_left), np.asarray(stereo.K_right))
    args = (view.T_cell_left_prior, obs, marker_truth.true, K, rs.T_left_right(stereo), 0.05)
    x = np.array([1e-4, -2e-4, 3e-4, 1e-4, 0.0, -1e-4])
    J, cols = rs._marker_jacobian(rs._pose_jacobian(x, *args), obs)
    assert np.array_equal(cols, np.unique(obs.marker))
    h = 1e-7
    for c, j in enumerate(cols[:3]):
        for a in range(3):
            Pp, Pm = marker_truth.true.copy(), marker_truth.true.copy()
            Pp[j, a] += h
            Pm[j, a] -= h
            num = (rs._residuals(x, *args[:2], Pp, *args[3:])
                   - rs._residuals(x, *args[:2], Pm, *args[3:])) / (2 * h)  # fmt: skip
            np.testing.assert_allclose(J[:, 3 * c + a], num, atol=1e-6 * np.abs(num).max())


def test_the_pose_jacobian_matches_finite_differences(small_cell, stereo, marker_truth):
    from cell.referencing import resection as rs

    _T, view = _stop(small_cell, stereo, marker_truth)
    obs = rs._Obs(view, stereo, {m: k for k, m in enumerate(marker_truth.ids)})
    K = (np.asarray(stereo.K_left), np.asarray(stereo.K_right))
    args = (view.T_cell_left_prior, obs, marker_truth.true, K, rs.T_left_right(stereo), 0.05)
    assert set(obs.side) == {0, 1}  # both cameras' rows
    for x in (np.zeros(6), np.array([2e-2, -3e-2, 1e-2, 1e-3, 0.0, -2e-3])):
        J = rs._pose_jacobian(x, *args)
        h = 1e-7
        for a in range(6):
            e = np.eye(6)[a] * h
            num = (rs._residuals(x + e, *args) - rs._residuals(x - e, *args)) / (2 * h)
            np.testing.assert_allclose(J[:, a], num, atol=1e-5 * np.abs(num).max())


def test_one_step_from_a_resected_pose_is_the_full_resection(small_cell, stereo, marker_truth,
                                                              network):  # fmt: skip
    """resect_near (one Gauss-Newton step) from a resected pose, with every centre moved by up
    to 0.002 px (a bias correction's size), lands where a full resection does; a marker moved
    since the survey still goes through the full resection and is refused by id."""
    from dataclasses import replace

    from cell.referencing.resection import resect_near

    ids, P, C = network
    _T, view = _stop(small_cell, stereo, marker_truth)
    first = resect(view, stereo, *network, 0.05)
    rng = np.random.default_rng(3)
    nudged = replace(
        view,
        uv_left={m: uv + rng.uniform(-0.002, 0.002, 2) for m, uv in view.uv_left.items()},
        uv_right={m: uv + rng.uniform(-0.002, 0.002, 2) for m, uv in view.uv_right.items()},
        T_cell_left_prior=first.T_cell_left,
    )
    full, near = resect(nudged, stereo, *network, 0.05), resect_near(nudged, stereo, *network, 0.05)
    assert near.ok and near.used == full.used and not near.refused
    c_left = np.array([0.0, 0.0, 0.25])  # where the hole is
    off_near = np.linalg.norm(near.point(c_left)[0] - full.point(c_left)[0])
    off_first = np.linalg.norm(first.point(c_left)[0] - full.point(c_left)[0])
    assert off_near < 1e-9 and off_near < 0.2 * off_first  # the step did the work
    np.testing.assert_allclose(near.covariance, full.covariance, rtol=1e-6)
    np.testing.assert_allclose(near.marker_sensitivity, full.marker_sensitivity, rtol=1e-6,
                               atol=1e-9 * np.abs(full.marker_sensitivity).max())  # fmt: skip
    moved = view.both()[0]
    P_survey = P.copy()
    P_survey[ids.index(moved)] += [0.0, 4e-4, 0.0]
    r = resect_near(nudged, stereo, ids, P_survey, C, 0.05)
    assert r.ok and moved in r.refused and moved not in r.used
