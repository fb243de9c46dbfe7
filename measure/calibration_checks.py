"""Checks that catch a person's mistakes in a stereo calibration before ``stereo.json`` is written.

- **Board size** (chessboards): OpenCV's classic detector returns an 8×6 grid on a 9×6 board,
  placed differently from view to view, and the calibration still converges (RMS 0.48 px on
  OpenCV's stereo sample). OpenCV's sector-based detector with ``CALIB_CB_LARGER`` reports the
  whole board it sees; a few views are asked, and a board larger than the given size in most of
  them refuses the calibration, naming the size seen.
- **Scale**: the square side fixes the scale of everything. A side of a metre or more is
  millimetres typed as metres (``--pitch 25``: an 83 m baseline) and is refused; a baseline
  outside 10 mm – 2 m is refused, naming the likely cause.
- **Outliers**: pairs whose reprojection RMS exceeds 3× the median are named (and can be
  dropped: :class:`measure.stereo_calibrate.CalibrateOptions`).
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass

import cv2
import numpy as np

from measure.calibration import StereoCalibration
from measure.target import TargetSpec, detection_copy, to_gray8

_SB_LARGER = (
    cv2.CALIB_CB_LARGER
    | cv2.CALIB_CB_NORMALIZE_IMAGE
    | cv2.CALIB_CB_EXHAUSTIVE
    | cv2.CALIB_CB_ACCURACY
)
#: views asked for the board's full size (each costs 0.1–0.4 s at 640×480)
SIZE_CENSUS_VIEWS = 4
#: a square side at or above this (metres) is refused as millimetres typed as metres
PITCH_MM_LIMIT_M = 1.0
#: a square side above this (metres) is warned about
PITCH_WARN_M = 0.2


@dataclass(frozen=True)
class CalibrationProblem:
    """Something wrong or doubtful about a calibration.

    Attributes:
        kind: ``"board_size"``, ``"pitch"``, ``"baseline"``, ``"outliers"`` or ``"rms"``.
        message: one line for a person: what was seen and the likely cause.
        refuse: the calibration must not be written (unless forced).
        pairs: the pairs concerned (outliers), by name.
    """

    kind: str
    message: str
    refuse: bool
    pairs: tuple[str, ...] = ()


def board_size_census(
    images: Sequence[np.ndarray], n_views: int = SIZE_CENSUS_VIEWS
) -> Counter[tuple[int, int]]:
    """How often each full board size (inner corners, larger first) is seen, over up to
    ``n_views`` images spread over ``images`` (OpenCV's SB detector with ``CALIB_CB_LARGER``)."""
    votes: Counter[tuple[int, int]] = Counter()
    if not images:
        return votes
    picks = np.unique(np.linspace(0, len(images) - 1, min(n_views, len(images))).round())
    for k in picks.astype(int):
        small, _ = detection_copy(to_gray8(images[k]))
        found, _, meta = cv2.findChessboardCornersSBWithMeta(small, (4, 4), flags=_SB_LARGER)
        if found and meta is not None:
            a, b = meta.shape[:2]
            votes[(max(a, b), min(a, b))] += 1
    return votes


def _oriented(size: tuple[int, int], spec: TargetSpec) -> tuple[int, int]:
    """``size`` as (cols, rows) in the orientation closest to the given ``spec``."""
    a, b = size
    if abs(a - spec.cols) + abs(b - spec.rows) <= abs(b - spec.cols) + abs(a - spec.rows):
        return a, b
    return b, a


def check_board_size(images: Sequence[np.ndarray], spec: TargetSpec) -> list[CalibrationProblem]:
    """Refuse when most views asked show a chessboard with more inner corners than given."""
    if spec.kind != "chessboard":
        return []
    votes = board_size_census(images)
    if not votes:
        return []
    size, n = votes.most_common(1)[0]
    asked = sum(votes.values())
    given = spec.cols * spec.rows
    if size[0] * size[1] <= given or n < max(2, (asked + 1) // 2):
        return []
    cols, rows = _oriented(size, spec)
    return [
        CalibrationProblem(
            "board_size",
            f"the board has {cols}x{rows} inner corners (seen in {n} of {asked} views asked), "
            f"not {spec.cols}x{spec.rows} as given (--cols {spec.cols} --rows {spec.rows}): "
            "a smaller grid sits at a different place on the board in different views and "
            f"corrupts the calibration; give --cols {cols} --rows {rows}",
            refuse=True,
        )
    ]


def size_hint(images: Sequence[np.ndarray], spec: TargetSpec) -> str:
    """When the given board is not found: the board size OpenCV sees instead, as a hint ("")."""
    if spec.kind != "chessboard":
        return ""
    votes = board_size_census(images)
    if not votes:
        return ""
    size, n = votes.most_common(1)[0]
    cols, rows = _oriented(size, spec)
    if (cols, rows) == (spec.cols, spec.rows):
        return ""
    return (
        f"a board of {cols}x{rows} inner corners is seen in {n} of {sum(votes.values())} "
        f"images asked: check --cols/--rows (given {spec.cols}x{spec.rows})"
    )


def check_pitch(spec: TargetSpec) -> list[CalibrationProblem]:
    """A square side of a metre or more is refused (millimetres typed as metres)."""
    p = spec.pitch_m
    if p >= PITCH_MM_LIMIT_M:
        return [
            CalibrationProblem(
                "pitch",
                f"square side {p:g} m: that looks like millimetres; the pitch is in metres "
                f"(--pitch {p / 1000:g} for {p:g} mm squares)",
                refuse=True,
            )
        ]
    if p > PITCH_WARN_M:
        return [
            CalibrationProblem(
                "pitch",
                f"square side {p:g} m is unusually large; the pitch is in metres "
                f"(--pitch {p / 1000:g} if you meant {p:g} mm)",
                refuse=False,
            )
        ]
    return []


def check_baseline(
    stereo: StereoCalibration, spec: TargetSpec, range_m: tuple[float, float]
) -> list[CalibrationProblem]:
    """Refuse a baseline outside ``range_m``, naming what the square side would have to be."""
    b = stereo.baseline_m
    lo, hi = range_m
    if lo <= b <= hi:
        return []
    if b > hi and lo <= b * 1e-3 <= hi:
        cause = (
            f"the square side looks like millimetres typed as metres; with "
            f"--pitch {spec.pitch_m * 1e-3:g} the baseline would be {b:.1f} mm"
        )
    else:
        cause = (
            f"the baseline scales with the square side: check --pitch (metres; "
            f"{spec.pitch_m * 1e3:g} mm squares given) and that left and right are two cameras"
        )
    return [
        CalibrationProblem(
            "baseline",
            f"baseline {b:.4g} m is outside {lo:g}–{hi:g} m: {cause}",
            refuse=True,
        )
    ]


def find_outliers(
    per_pair_px: Sequence[tuple[str, float]], factor: float, floor_px: float
) -> list[str]:
    """Pairs whose RMS exceeds ``factor`` × the median RMS (and ``floor_px``)."""
    if len(per_pair_px) < 3:
        return []
    med = float(np.median([e for _, e in per_pair_px]))
    limit = max(factor * med, floor_px)
    return [name for name, e in per_pair_px if e > limit]


def outlier_problem(
    per_pair_px: Sequence[tuple[str, float]], names: Sequence[str], factor: float, dropped: bool
) -> CalibrationProblem:
    """The warning that names the outlier pairs (and whether they were dropped)."""
    med = float(np.median([e for _, e in per_pair_px]))
    errs = dict(per_pair_px)
    listed = ", ".join(f"{n} ({errs[n]:.2f} px)" for n in names)
    tail = (
        "dropped and calibrated again"
        if dropped
        else "check them (motion blur, a board that moved between the two shots, a bad "
        "corner) or drop them with --drop-outliers"
    )
    return CalibrationProblem(
        "outliers",
        f"{len(names)} pair(s) above {factor:g}x the median RMS {med:.3f} px: {listed}; {tail}",
        refuse=False,
        pairs=tuple(names),
    )
