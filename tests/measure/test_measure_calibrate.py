"""Stereo calibration from rendered target pairs with known truth, and ``holecell calibrate``."""

from __future__ import annotations

from functools import lru_cache

import cv2
import numpy as np
import pytest
from measure_helpers import small_stereo

from cell.cli import main
from measure import StereoCalibration, head_frame
from measure.errors import CalibrationTargetError
from measure.stereo_calibrate import calibrate_stereo
from measure.synth.targets import render_target_pair
from measure.target import TargetSpec, detect_target

CIRCLES = TargetSpec("circles", 4, 7, 2.2e-3)
BOARD = TargetSpec("chessboard", 8, 5, 3e-3)


def _pose(spec: TargetSpec, rng: np.random.Generator) -> np.ndarray:
    P = np.eye(4)
    rv = rng.uniform(-0.5, 0.5, 3) * np.array([1.0, 1.0, 0.4])
    P[:3, :3] = cv2.Rodrigues(rv)[0]
    c = spec.object_points()[:, :2].mean(axis=0)
    P[:3, 3] = np.array([*rng.uniform(-2e-3, 2e-3, 2), 0.25]) - P[:3, :3] @ np.array([*c, 0.0])
    return head_frame(small_stereo()) @ P


@lru_cache(maxsize=2)
def _pairs(kind: str, n: int) -> tuple:
    spec = CIRCLES if kind == "circles" else BOARD
    rng = np.random.default_rng(5)
    out = []
    for i in range(n):
        r = render_target_pair(small_stereo(), spec, _pose(spec, rng), seed=i)
        out.append((f"pair{i}", r.left, r.right))
    return tuple(out)


def _rot_err_deg(A: np.ndarray, B: np.ndarray) -> float:
    return float(np.degrees(np.arccos(np.clip((np.trace(A @ B.T) - 1) / 2, -1, 1))))


def test_detector_finds_features_at_the_projected_truth():
    rng = np.random.default_rng(1)
    T = _pose(CIRCLES, rng)
    r = render_target_pair(small_stereo(), CIRCLES, T)
    pts, why = detect_target(r.left, CIRCLES)
    assert why == ""
    truth = small_stereo().project((T[:3, :3] @ CIRCLES.object_points().T).T + T[:3, 3], "left")
    assert np.abs(pts - truth).max() < 0.15


def test_calibration_recovers_the_head():
    truth = small_stereo()
    res = calibrate_stereo(_pairs("circles", 7), CIRCLES)
    st = res.stereo
    assert res.rejected == [] and len(res.per_pair_px) == 7
    assert res.rms_px < 0.15 and all(e < 0.3 for _, e in res.per_pair_px)
    assert st.K_left[0, 0] == pytest.approx(truth.K_left[0, 0], rel=0.015)
    assert st.baseline_m == pytest.approx(truth.baseline_m, rel=0.02)
    assert _rot_err_deg(st.R, truth.R) < 0.5


def test_bad_pairs_are_rejected_with_a_reason():
    good = list(_pairs("circles", 7))[:4]
    blank = np.full_like(good[0][1], 128)
    blurred = cv2.GaussianBlur(good[0][1], (0, 0), 6.0)
    pairs = [
        *good,
        ("blank", blank, blank),
        ("blurred", blurred, blurred),
        ("small", good[0][1][:400], good[0][2][:400]),
    ]
    res = calibrate_stereo(pairs, CIRCLES)
    reasons = dict(res.rejected)
    assert "not found" in reasons["blank"]
    assert "blurred" in reasons["blurred"] or "not found" in reasons["blurred"]
    assert "differs" in reasons["small"]
    with pytest.raises(CalibrationTargetError, match="usable image pairs"):
        calibrate_stereo([("blank", blank, blank)] * 4, CIRCLES)


def test_chessboard_detection_and_blur_check():
    rng = np.random.default_rng(2)
    r = render_target_pair(small_stereo(), BOARD, _pose(BOARD, rng), supersample=2)
    pts, why = detect_target(r.left, BOARD)
    assert why == "" and len(pts) == 40
    _, why = detect_target(cv2.GaussianBlur(r.left, (0, 0), 3.5), BOARD)
    assert "blurred" in why or "not found" in why


def test_cli_writes_stereo_json(tmp_path, capsys):
    for name, left, right in _pairs("circles", 7):
        cv2.imwrite(str(tmp_path / f"L_{name}.png"), left)
        cv2.imwrite(str(tmp_path / f"R_{name}.png"), right)
    cv2.imwrite(str(tmp_path / "L_x_blank.png"), np.full((512, 640), 128, np.uint8))
    cv2.imwrite(str(tmp_path / "R_x_blank.png"), np.full((512, 640), 128, np.uint8))
    out = tmp_path / "stereo.json"
    args = ["calibrate", "--left", str(tmp_path / "L_*.png"), "--right", str(tmp_path / "R_*.png")]
    args += [
        "--pattern",
        "circles",
        "--cols",
        "4",
        "--rows",
        "7",
        "--pitch",
        "0.0022",
        "-o",
        str(out),
        "--bootstrap",
        "10",
    ]
    assert main(args) == 0
    text = capsys.readouterr().out
    assert "RMS reprojection error" in text and "rejected: target not found" in text
    st = StereoCalibration.load(out)
    assert st.baseline_m == pytest.approx(0.1, rel=0.02)
    # too few usable pairs: a clear error, and the existing file is kept
    before = out.read_text()
    bad = [
        "calibrate",
        "--left",
        str(tmp_path / "L_x_blank.png"),
        "--right",
        str(tmp_path / "R_x_blank.png"),
    ]
    bad += [
        "--pattern",
        "circles",
        "--cols",
        "4",
        "--rows",
        "7",
        "--pitch",
        "0.0022",
        "-o",
        str(out),
    ]
    assert main(bad) == 2
    assert "usable image pairs" in capsys.readouterr().err
    assert out.read_text() == before
