"""Calibration that catches mistakes: detector retry, wrong board size, millimetre pitch,
outlier pairs, and the parameter uncertainties stored in stereo.json."""

from __future__ import annotations

import json
from functools import lru_cache

import cv2
import numpy as np
import pytest
from measure_helpers import small_stereo

from cell.cli import main
from measure import StereoCalibration, head_frame
from measure.calibration_covariance import Camera, mono_covariance
from measure.stereo_calibrate import CalibrateOptions, calibrate_points, calibrate_stereo
from measure.synth.targets import render_target_pair
from measure.target import TargetSpec, find_target

BOARD = TargetSpec("chessboard", 8, 5, 3e-3)
_CLASSIC = cv2.CALIB_CB_ADAPTIVE_THRESH | cv2.CALIB_CB_NORMALIZE_IMAGE


def _plate_pose(spec: TargetSpec, rvec, offset_m=(0.0, 0.0), z_m: float = 0.25) -> np.ndarray:
    """``T_left_plate`` with the plate centre on the head axis at ``z_m``."""
    P = np.eye(4)
    P[:3, :3] = cv2.Rodrigues(np.asarray(rvec, float))[0]
    c = spec.object_points()[:, :2].mean(axis=0)
    P[:3, 3] = np.array([*offset_m, z_m]) - P[:3, :3] @ np.array([*c, 0.0])
    return head_frame(small_stereo()) @ P


@lru_cache(maxsize=1)
def _board_pairs(n: int = 7) -> tuple:
    rng = np.random.default_rng(11)
    out = []
    for i in range(n):
        rv = rng.uniform(-0.5, 0.5, 3) * np.array([1.0, 1.0, 0.4])
        T = _plate_pose(BOARD, rv, rng.uniform(-2e-3, 2e-3, 2))
        r = render_target_pair(small_stereo(), BOARD, T, seed=i)
        out.append((f"pair{i}", r.left, r.right))
    return tuple(out)


def test_a_board_the_fast_check_misses_is_found_by_the_plain_detector():
    # a plate turned 60° away: OpenCV's fast pre-check gives up, the plain detector finds it
    T = _plate_pose(BOARD, (0.1, -1.0, 0.25))
    r = render_target_pair(small_stereo(), BOARD, T, seed=0)
    found, _ = cv2.findChessboardCorners(
        r.left, BOARD.pattern_size, flags=_CLASSIC | cv2.CALIB_CB_FAST_CHECK
    )
    assert not found
    det = find_target(r.left, BOARD)
    assert det.reason == "" and det.detector == "plain"
    X = (T[:3, :3] @ BOARD.object_points().T).T + T[:3, 3]
    assert np.abs(det.points - small_stereo().project(X, "left")).max() < 0.3


def test_good_boards_calibrate_without_problems_and_carry_uncertainties():
    res = calibrate_stereo(_board_pairs(), BOARD)
    assert res.problems == [] and res.refused == []
    assert all(d == ("fast", "fast") for d in res.detectors.values())
    u = res.stereo.uncertainty
    assert u is not None and u.method == "jacobian"
    assert u.per_view_rms_px.shape == (7, 2) and u.rms_px == pytest.approx(res.rms_px)
    assert np.all(u.K_std_left_px > 0) and np.all(u.T_std_m > 0) and np.all(u.rvec_std_rad > 0)
    assert u.dist_std_left[4] == 0.0  # k3 is fixed, not estimated
    # the truth lies within a few predicted sigmas of the estimate
    truth = small_stereo()
    assert np.all(np.abs(res.stereo.T - truth.T) < 5 * u.T_std_m + 1e-6)


def test_too_small_board_size_is_refused_naming_the_size_seen():
    from measure.calibration_checks import check_board_size

    left = [p[1] for p in _board_pairs()]
    small = TargetSpec("chessboard", 7, 5, 3e-3)
    (prob,) = check_board_size(left, small)
    assert prob.refuse and prob.kind == "board_size" and "8x5" in prob.message
    assert check_board_size(left, BOARD) == []
    # a board size that is found in too few pairs: the error says which size is there
    from measure.errors import CalibrationTargetError

    with pytest.raises(CalibrationTargetError, match="8x5 inner corners"):
        calibrate_stereo(_board_pairs()[:3], TargetSpec("chessboard", 9, 5, 3e-3))


def test_millimetre_pitch_is_refused_with_the_likely_cause():
    mm = TargetSpec("chessboard", 8, 5, 3.0)  # 3 mm typed as 3 (metres)
    res = calibrate_stereo(_board_pairs(), mm)
    kinds = {p.kind for p in res.refused}
    assert kinds == {"pitch", "baseline"}
    text = " ".join(p.message for p in res.refused)
    assert "--pitch 0.003" in text and "millimetres" in text
    assert res.stereo.baseline_m == pytest.approx(100.0, rel=0.05)  # 0.1 m × 1000


def test_outlier_pair_is_named_and_can_be_dropped():
    pairs = list(_board_pairs())
    name, left, right = pairs[3]
    # the plate moved between the two exposures: the right view is 3 px lower
    pairs[3] = (name, left, np.roll(right, 3, axis=0))
    res = calibrate_stereo(pairs, BOARD)
    (prob,) = [p for p in res.problems if p.kind == "outliers"]
    assert prob.pairs == (name,) and not prob.refuse and "--drop-outliers" in prob.message
    dropped = calibrate_stereo(pairs, BOARD, CalibrateOptions(drop_outliers=True))
    assert dropped.dropped == [name] and name not in dict(dropped.per_pair_px)
    assert "dropped" in dict(dropped.rejected)[name]
    assert dropped.rms_px < 0.5 * res.rms_px


def test_our_single_camera_covariance_equals_opencvs_standard_deviations():
    st, spec, left, _ = _wide_views(8)
    rng = np.random.default_rng(0)
    img = [(p + rng.normal(0, 0.2, p.shape)).astype(np.float32) for p in left]
    obj = [spec.object_points().astype(np.float32)] * len(img)
    _, K, d, rv, tv, std_in, _, _ = cv2.calibrateCameraExtended(
        obj, img, st.image_size, None, None, flags=cv2.CALIB_FIX_K3
    )
    ours = mono_covariance(spec.object_points(), img, Camera(K, d.ravel()), rv, tv)
    np.testing.assert_allclose(ours.std[:8], std_in.ravel()[:8], rtol=1e-4)


def _wide_views(n: int):
    """A wide-angle 640×480 head (f 520 px, 90 mm baseline), n views of a 9×6 board of 25 mm
    at 0.5–0.8 m: feature positions without noise."""
    K = np.array([[520.0, 0, 318], [0, 522.0, 242], [0, 0, 1]])
    st = StereoCalibration(
        (640, 480),
        K,
        np.array([-0.25, 0.1, 0.001, -0.0005, 0.0]),
        K * [[1.01], [1.01], [1]],
        np.array([-0.22, 0.08, 0, 0, 0.0]),
        cv2.Rodrigues(np.array([0.01, -0.03, 0.005]))[0],
        np.array([-0.09, 0.001, 0.002]),
    )
    spec = TargetSpec("chessboard", 9, 6, 0.025)
    obj = spec.object_points()
    rng = np.random.default_rng(3)
    left, right = [], []
    while len(left) < n:
        R = cv2.Rodrigues(rng.uniform(-0.6, 0.6, 3) * np.array([1, 1, 0.5]))[0]
        t = np.array([*rng.uniform(-0.1, 0.1, 2), rng.uniform(0.5, 0.8)])
        X = (R @ (obj - [*obj[:, :2].mean(axis=0), 0]).T).T + t
        pl, pr = st.project(X, "left"), st.project(X, "right")
        if all(p.min() > 5 and (p < [635, 475]).all() for p in (pl, pr)):
            left.append(pl)
            right.append(pr)
    return st, spec, left, right


def test_predicted_standard_deviations_match_the_spread_over_noise_seeds():
    st, spec, left, right = _wide_views(8)
    est, pred = [], []
    for seed in range(20):
        rng = np.random.default_rng(100 + seed)
        L = [p + rng.normal(0, 0.2, p.shape) for p in left]
        R = [p + rng.normal(0, 0.2, p.shape) for p in right]
        c = calibrate_points(L, R, spec, st.image_size)
        u = c.uncertainty
        est.append([c.K_left[0, 0], c.K_right[0, 2], *c.T, *cv2.Rodrigues(c.R)[0].ravel()])
        pred.append([u.K_std_left_px[0], u.K_std_right_px[2], *u.T_std_m, *u.rvec_std_rad])
    ratio = np.std(est, axis=0, ddof=1) / np.mean(pred, axis=0)
    assert np.all((ratio > 0.6) & (ratio < 1.6)), ratio


def test_cli_refuses_the_millimetre_pitch_and_writes_uncertainties(tmp_path, capsys):
    for name, left, right in _board_pairs()[:4]:
        cv2.imwrite(str(tmp_path / f"L_{name}.png"), left)
        cv2.imwrite(str(tmp_path / f"R_{name}.png"), right)
    out = tmp_path / "stereo.json"
    base = ["calibrate", "--left", str(tmp_path / "L_*.png"), "--right", str(tmp_path / "R_*.png")]
    base += ["--cols", "8", "--rows", "5", "-o", str(out), "--bootstrap", "10"]
    assert main([*base, "--pitch", "3"]) == 2
    cap = capsys.readouterr()
    assert "refused: square side 3 m" in cap.out and "not written" in cap.err
    assert not out.exists()
    assert main([*base, "--pitch", "0.003"]) == 0
    assert "bootstrap" in capsys.readouterr().out
    data = json.loads(out.read_text())
    assert data["uncertainty"]["method"].startswith("max(jacobian, bootstrap")
    assert StereoCalibration.load(out).uncertainty.T_std_m[0] > 0
    assert main([*base, "--pitch", "3", "--force", "-o", str(tmp_path / "forced.json")]) == 0
    assert StereoCalibration.load(tmp_path / "forced.json").baseline_m > 50


def test_large_images_are_searched_scaled_down_and_refined_at_full_resolution():
    from measure.target import DETECT_MAX_SIDE_PX

    _, left, _ = _board_pairs()[0]
    big = np.full((1100, 1500), 64, np.uint8)  # the 640×512 view inside a larger frame
    big[200:712, 300:940] = left
    assert max(big.shape) > DETECT_MAX_SIDE_PX
    small = find_target(left, BOARD)
    det = find_target(big, BOARD)
    assert det.reason == "" and det.detector == "fast"
    # found on the scaled copy, refined in the full-resolution image: the same corners
    np.testing.assert_allclose(det.points, small.points + np.array([300.0, 200.0]), atol=0.02)


def test_left_and_right_grids_turned_by_180_degrees_are_put_in_one_order():
    from measure.stereo_calibrate import _orient

    _, left, right = _board_pairs()[1]
    pl, pr = find_target(left, BOARD).points, find_target(right, BOARD).points
    np.testing.assert_array_equal(_orient(pl, pr[::-1], BOARD), pr)
    np.testing.assert_array_equal(_orient(pl, pr, BOARD), pr)
