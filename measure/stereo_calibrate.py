"""Stereo calibration from image pairs of a plate target (OpenCV's detectors and solvers).

Each pair is checked (target found in both images, all features, sharp enough) and
rejected with a reason otherwise. Both cameras are calibrated alone
(``cv2.calibrateCamera``, k3 fixed), then jointly (``cv2.stereoCalibrate``, intrinsics as
the initial guess). Per-pair RMS reprojection errors come from the joint solution.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

import cv2
import numpy as np

from measure.calibration import StereoCalibration
from measure.errors import CalibrationTargetError
from measure.target import TargetSpec, detect_target

MIN_PAIRS = 3


@dataclass(frozen=True)
class CalibrationResult:
    """The calibration, its RMS reprojection error (px), per-pair errors and rejections."""

    stereo: StereoCalibration
    rms_px: float
    per_pair_px: list[tuple[str, float]]
    rejected: list[tuple[str, str]]


def _detect_pairs(pairs, spec: TargetSpec, size: tuple[int, int] | None):
    used, rejected = [], []
    for name, left, right in pairs:
        if left.shape[:2] != right.shape[:2]:
            (hl, wl), (hr, wr) = left.shape[:2], right.shape[:2]
            rejected.append((name, f"left {wl}x{hl} and right {wr}x{hr} differ in size"))
            continue
        if size is not None and (left.shape[1], left.shape[0]) != size:
            rejected.append(
                (
                    name,
                    f"image size {left.shape[1]}x{left.shape[0]} differs from {size[0]}x{size[1]}",
                )
            )
            continue
        size = (left.shape[1], left.shape[0])
        pl, why_l = detect_target(left, spec)
        pr, why_r = (None, "") if pl is None else detect_target(right, spec)
        if pl is None or pr is None:
            rejected.append((name, f"{why_l} (left)" if pl is None else f"{why_r} (right)"))
            continue
        used.append((name, pl.astype(np.float32), pr.astype(np.float32)))
    return used, rejected, size


def calibrate_stereo(
    pairs: Iterable[tuple[str, np.ndarray, np.ndarray]], spec: TargetSpec
) -> CalibrationResult:
    """Calibrate from ``(name, left, right)`` gray image pairs of ``spec``."""
    used, rejected, size = _detect_pairs(list(pairs), spec, None)
    if len(used) < MIN_PAIRS:
        raise CalibrationTargetError(
            f"only {len(used)} usable image pairs, at least {MIN_PAIRS} needed", rejected
        )
    obj = [spec.object_points().astype(np.float32)] * len(used)
    img_l = [u[1] for u in used]
    img_r = [u[2] for u in used]
    flags = cv2.CALIB_FIX_K3
    _, K1, d1, _, _ = cv2.calibrateCamera(obj, img_l, size, None, None, flags=flags)
    _, K2, d2, _, _ = cv2.calibrateCamera(obj, img_r, size, None, None, flags=flags)
    crit = (cv2.TERM_CRITERIA_COUNT | cv2.TERM_CRITERIA_EPS, 100, 1e-10)
    n = len(used)
    rms, K1, d1, K2, d2, R, T, _, _, _, _, errs = cv2.stereoCalibrateExtended(
        obj,
        img_l,
        img_r,
        K1,
        d1,
        K2,
        d2,
        size,
        np.eye(3),
        np.zeros((3, 1)),
        np.zeros((n, 3, 1)),
        np.zeros((n, 3, 1)),
        flags=cv2.CALIB_USE_INTRINSIC_GUESS | cv2.CALIB_FIX_K3,
        criteria=crit,
    )
    errs = np.asarray(errs).reshape(n, 2)
    per_pair = [
        (u[0], float(np.sqrt(0.5 * (e[0] ** 2 + e[1] ** 2))))
        for u, e in zip(used, errs, strict=True)
    ]
    stereo = StereoCalibration(
        image_size=size,
        K_left=K1,
        dist_left=d1.ravel()[:5],
        K_right=K2,
        dist_right=d2.ravel()[:5],
        R=R,
        T=T.ravel(),
        source="<calibration>",
    )
    return CalibrationResult(
        stereo=stereo, rms_px=float(rms), per_pair_px=per_pair, rejected=rejected
    )
