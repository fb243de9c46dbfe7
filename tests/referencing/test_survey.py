"""The survey on simulated observations: accuracy against the truth, the refusals, outliers,
the scale without bars, GTSAM against the SciPy reference, markers.json."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from referencing_cells import small_cell_text, survey_observations

from cell.config import builtin_cell_path, parse_cell
from cell.referencing import MarkersFileError, SurveyRefusedError, load_markers, survey
from cell.referencing.markersfile import check_markers, save_markers
from cell.referencing.survey.gauge import rigid_fit, to_gauge
from cell.referencing.survey.problem import build_problem
from cell.referencing.survey.refusals import usable_views
from cell.referencing.survey.solve_gtsam import solve_gtsam
from cell.referencing.survey.solve_scipy import solve_scipy
from cell.referencing.synthetic import draw_marker_truth


@pytest.fixture(scope="module")
def surveyed(small_cell, stereo, marker_truth):
    views = survey_observations(small_cell, stereo, marker_truth)
    return views, survey(small_cell, stereo, views)


def _rigid_error(P: np.ndarray, Q: np.ndarray) -> np.ndarray:
    T = rigid_fit(P, Q)
    return np.linalg.norm(P @ T[:3, :3].T + T[:3, 3] - Q, axis=1)


def test_the_network_agrees_with_the_truth_within_its_stated_sigma(surveyed, marker_truth):
    _views, res = surveyed
    rows = [marker_truth.ids.index(m) for m in res.marker_ids]
    e = _rigid_error(res.positions_cell, marker_truth.true[rows])
    assert np.sqrt(np.mean(e**2)) < 10e-6 and e.max() < 25e-6
    assert res.gauge == "fixture markers" and 0.8 < res.variance_factor < 1.25
    assert np.median(res.sigma_m()) < 10e-6 and res.scale_sigma_ppm < 10
    assert not res.outliers and res.stereo is not None


def test_gtsam_agrees_with_the_scipy_reference(small_cell, stereo, surveyed, marker_truth):
    views, _ = surveyed
    ids = list(marker_truth.ids)
    bars = [(b.from_, b.to, b.length_m, b.U_m) for b in small_cell.scale_bars]
    kept, _ = usable_views(views, ids, marker_truth.nominal)
    problem = build_problem(kept, stereo, ids, marker_truth.nominal, bars, 0.05)
    g, s = solve_gtsam(problem, covariance=False), solve_scipy(problem)
    gauged = [
        to_gauge(x.points, None, marker_truth.nominal, marker_truth.on_fixture).points
        for x in (g, s)
    ]  # the solvers' own datum is arbitrary: compare in the gauge
    assert np.abs(gauged[0] - gauged[1]).max() < 2e-6


def test_a_marker_seen_too_rarely_is_refused_by_name(small_cell, stereo, marker_truth):
    views = survey_observations(small_cell, stereo, marker_truth)
    gone = "P003"
    for v in views[: len(views) - 2]:
        v.uv_left.pop(gone, None)
        v.uv_right.pop(gone, None)
    left = sum(gone in v.either() for v in views)
    if left >= 3:
        for v in views:
            v.uv_left.pop(gone, None)
            v.uv_right.pop(gone, None)
    with pytest.raises(SurveyRefusedError, match=f"marker {gone}: seen in [0-2] views"):
        survey(small_cell, stereo, views)


def test_a_network_in_two_pieces_is_refused(small_cell, stereo, marker_truth):
    views = survey_observations(small_cell, stereo, marker_truth)
    fixture = {m.id for m in small_cell.reference_markers if m.on == "fixture"}
    split = []
    for v in views:  # no view sees the table and the part together
        part = set(v.either()) - fixture
        drop = fixture if len(part) >= 2 else part
        split.append(type(v)(v.view_id, {m: p for m, p in v.uv_left.items() if m not in drop},
                             {m: p for m, p in v.uv_right.items() if m not in drop},
                             v.T_cell_left_prior))  # fmt: skip
    with pytest.raises(SurveyRefusedError, match="network: in 2 pieces"):
        survey(small_cell, stereo, split)


def test_rays_meeting_at_a_narrow_angle_are_refused(small_cell, stereo, marker_truth):
    views = survey_observations(small_cell, stereo, marker_truth)
    target = "P001"
    first = next(v for v in views if target in v.either())
    axis = first.T_cell_left_prior[:3, 3] - marker_truth.nominal[marker_truth.ids.index(target)]
    narrow = []
    for v in views:
        ray = v.T_cell_left_prior[:3, 3] - marker_truth.nominal[marker_truth.ids.index(target)]
        cos = ray @ axis / np.linalg.norm(ray) / np.linalg.norm(axis)
        if cos < np.cos(np.radians(8)):  # only views within 8 deg of the first see it
            v.uv_left.pop(target, None)
            v.uv_right.pop(target, None)
        narrow.append(v)
    with pytest.raises(SurveyRefusedError, match=f"marker {target}: (its rays meet|seen in)"):
        survey(small_cell, stereo, narrow)


def test_an_outlier_is_named_dropped_and_the_rest_holds(small_cell, stereo, marker_truth):
    views = survey_observations(small_cell, stereo, marker_truth)
    v = next(v for v in views if "P002" in v.uv_left)
    v.uv_left["P002"] = v.uv_left["P002"] + np.array([3.0, -2.0])  # a misdetection
    res = survey(small_cell, stereo, views)
    assert [(o[0], o[1], o[2]) for o in res.outliers] == [(v.view_id, "P002", "left")]
    assert any("P002" in w and "dropped" in w for w in res.warnings)


def test_a_marker_misread_far_off_is_found_without_bending_the_head(small_cell, stereo,
                                                                     marker_truth):  # fmt: skip
    """A code read on the wrong marker (hundreds of pixels off, as in a demo survey): the robust
    first round keeps it from dragging the self-calibrated head, so it alone is dropped."""
    views = survey_observations(small_cell, stereo, marker_truth)
    v = next(v for v in views if "P002" in v.uv_right)
    v.uv_right["P002"] = v.uv_right["P002"] + np.array([640.0, -450.0])
    res = survey(small_cell, stereo, views)
    assert [(o[0], o[1], o[2]) for o in res.outliers] == [(v.view_id, "P002", "right")]
    rows = [marker_truth.ids.index(m) for m in res.marker_ids]
    e = _rigid_error(res.positions_cell, marker_truth.true[rows])
    assert np.sqrt(np.mean(e**2)) < 10e-6


def test_without_scale_bars_the_survey_says_its_scale_uncertainty(stereo, marker_truth):
    cell = parse_cell(small_cell_text(bars=False), "nobars.yaml", builtin_cell_path())
    truth = draw_marker_truth(cell, seed=3)
    res = survey(cell, stereo, survey_observations(cell, stereo, truth))
    assert res.scale_sigma_ppm >= 100 and "baseline alone" in res.scale_source
    assert any("no scale bars" in w and "100 ppm" in w for w in res.warnings)


def test_markers_file_round_trip_and_refusals(surveyed, small_cell, stereo, tmp_path: Path):
    _views, res = surveyed
    path = save_markers(tmp_path / "markers.json", res, small_cell, stereo)
    doc, ids, P, C = load_markers(path)
    assert ids == res.marker_ids and np.allclose(P, res.positions_cell)
    assert np.allclose(C, res.covariance)
    check_markers(doc, str(path), small_cell, stereo)
    other = parse_cell(small_cell_text().replace("id: P001", "id: Q001"), "o.yaml",
                       builtin_cell_path())  # fmt: skip
    with pytest.raises(MarkersFileError, match="cell_fingerprint"):
        check_markers(doc, str(path), other, stereo)
    with pytest.raises(MarkersFileError, match=r"created_utc: the survey is .* days old"):
        check_markers(doc | {"created_utc": "2026-01-01T00:00:00Z"}, str(path), small_cell, stereo)
    path.write_text(json.dumps(doc | {"version": 9}))
    with pytest.raises(MarkersFileError, match="version"):
        load_markers(path)


def test_the_self_calibrated_head_carries_the_adjustments_uncertainty(surveyed, stereo):
    """The survey's head states the marginal σ of its camera matrices and rig, tighter than the
    default figures of a careful calibration it started from; k3, not estimated, keeps those."""
    from cell.uncertainty.calibration import default_uncertainty

    u, d = surveyed[1].stereo.uncertainty, default_uncertainty(stereo)
    assert u is not None and "survey" in u.method
    assert np.all(u.K_std_left_px < d.K_std_left_px) and np.all(u.T_std_m < d.T_std_m)
    assert u.dist_std_left[4] == d.dist_std_left[4]


def test_the_dense_covariance_agrees_with_gtsams_marginals(small_cell, stereo, surveyed,
                                                           marker_truth):  # fmt: skip
    """The fall-back when GTSAM's Cholesky cannot factor a network: the same information
    matrix, scaled and factored densely, gives the same marginals."""
    import gtsam

    from cell.referencing.survey import solve_gtsam as sg

    views, _ = surveyed
    ids = list(marker_truth.ids)
    bars = [(b.from_, b.to, b.length_m, b.U_m) for b in small_cell.scale_bars]
    kept, _ = usable_views(views, ids, marker_truth.nominal)
    problem = build_problem(kept, stereo, ids, marker_truth.nominal, bars, 0.05)
    graph, values = sg._graph(problem)
    result = gtsam.LevenbergMarquardtOptimizer(graph, values).optimize()
    gt_cov, gt_head = sg._covariances(problem, graph, result)
    de_cov, de_head = sg._dense_covariances(problem, graph, result)
    sd = np.sqrt(np.diag(gt_cov))
    assert np.abs(np.sqrt(np.diag(de_cov)) / sd - 1.0).max() < 1e-3
    corr = lambda C: C / np.sqrt(np.outer(np.diag(C), np.diag(C)))  # noqa: E731
    assert np.abs(corr(de_cov) - corr(gt_cov)).max() < 1e-3
    for a, b in zip(gt_head, de_head, strict=True):
        assert np.abs(np.sqrt(np.diag(b)) / np.sqrt(np.diag(a)) - 1.0).max() < 1e-3


def test_the_covariances_are_stated_at_the_a_posteriori_noise_above_the_floor(
    surveyed, small_cell, stereo, tmp_path: Path
):
    from cell.referencing.network import load_network
    from cell.referencing.sigma import SIGMA_FLOOR_PX, effective_sigma_px

    assert effective_sigma_px(0.05, (0.006 / 0.05) ** 2) == SIGMA_FLOOR_PX  # a clean render
    assert np.isclose(effective_sigma_px(0.05, 4.0), 0.1)  # a detector worse than stated
    assert np.isclose(effective_sigma_px(0.05, (0.006 / 0.05) ** 2, 0.0), 0.006)  # no floor
    _views, res = surveyed  # simulated at the stated 0.05 px: the variance factor is about 1
    assert res.sigma_floor_px == SIGMA_FLOOR_PX  # a real head's floor by default
    assert np.isclose(res.sigma_effective_px, 0.05 * np.sqrt(res.variance_factor), rtol=0.05)
    path = save_markers(tmp_path / "markers.json", res, small_cell, stereo)
    net = load_network(path, small_cell, stereo)
    assert net.sigma_px == 0.05
    assert net.image_sigma_px == res.sigma_effective_px
    doc = json.loads(path.read_text())
    assert doc["figures"]["sigma_floor_px"] == SIGMA_FLOOR_PX
    doc["figures"]["sigma_effective_px"] = -1
    path.write_text(json.dumps(doc))
    with pytest.raises(MarkersFileError, match=r"figures\.sigma_effective_px"):
        load_network(path, small_cell, stereo)


@pytest.fixture(scope="module")
def clean(small_cell, stereo, marker_truth):
    """The small cell surveyed on clean detections (0.006 px, the renderer's) with no floor."""
    from cell.referencing.survey.survey import SurveyOptions

    views = survey_observations(small_cell, stereo, marker_truth, seed=1, sigma_px=0.006)
    return survey(small_cell, stereo, views, SurveyOptions(sigma_floor_px=0.0))


def test_clean_images_are_weighed_at_their_own_noise_and_the_bars_keep_their_sigma(
    surveyed, clean, small_cell, marker_truth
):
    """The final adjustment weighs the pixels at their a posteriori noise, the scale bars at
    their own U: on images 8 times cleaner than stated the scale's sigma cannot go below what
    the bars give, where scaling a covariance computed at the stated noise by the variance
    factor (the old way) stated it at 0.12 of the 0.05 px figure, below the bars' own."""
    _views, res = surveyed
    assert 0.005 < clean.sigma_effective_px < 0.0075
    assert 0.01 < clean.variance_factor < 0.025  # at the stated 0.05 px
    bars_ppm = 1e6 / np.sqrt(sum((2 * b.length_m / b.U_m) ** 2 for b in small_cell.scale_bars))
    assert clean.scale_sigma_ppm > 0.9 * bars_ppm
    assert res.scale_sigma_ppm * np.sqrt(clean.variance_factor) < 0.9 * bars_ppm  # the old way
    # the network's stated covariance against its true error (Mahalanobis, the gauge removed)
    rows = [marker_truth.ids.index(m) for m in clean.marker_ids]
    true, fx = marker_truth.true[rows], marker_truth.on_fixture[rows]
    G = rigid_fit(true[fx], marker_truth.nominal[rows][fx])
    e = (clean.positions_cell - (true @ G[:3, :3].T + G[:3, 3])).ravel()
    w, V = np.linalg.eigh(clean.covariance)
    k = w > w.max() * 1e-10
    chi2_per_dof = float(np.sum((V[:, k].T @ e) ** 2 / w[k]) / k.sum())
    assert 0.5 < chi2_per_dof < 1.6
