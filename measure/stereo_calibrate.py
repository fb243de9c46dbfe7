"""Stereo calibration from image pairs of a plate target (OpenCV's detectors and solvers).

Each pair is checked (target found in both images, all features, sharp enough) and
rejected with a reason otherwise; each image is tried with every detector of
:func:`measure.target.find_target` before it is rejected. Both cameras are calibrated alone
(``cv2.calibrateCamera``, k3 fixed), then jointly (``cv2.stereoCalibrateExtended``, intrinsics
as the initial guess). Per-pair RMS reprojection errors come from the joint solution, the
parameter uncertainties from its Jacobian (:mod:`measure.calibration_covariance`) and, when
asked, a bootstrap over the pairs. :mod:`measure.calibration_checks` then looks for a
person's mistakes (board size, square side in millimetres, outlier pairs): a
:class:`CalibrationResult` with a refusing problem must not be written.
"""

from __future__ import annotations

import logging
from collections.abc import Iterable
from dataclasses import dataclass, field, replace

import cv2
import numpy as np

from measure import calibration_checks as checks
from measure.calibration import StereoCalibration
from measure.calibration_checks import CalibrationProblem
from measure.calibration_covariance import Camera, stereo_covariance
from measure.calibration_uncertainty import CalibrationUncertainty
from measure.errors import CalibrationTargetError
from measure.target import TargetSpec, find_target

log = logging.getLogger(__name__)

MIN_PAIRS = 3
_CRITERIA = (cv2.TERM_CRITERIA_COUNT | cv2.TERM_CRITERIA_EPS, 100, 1e-10)


@dataclass(frozen=True)
class CalibrateOptions:
    """How :func:`calibrate_stereo` checks and solves.

    Attributes:
        drop_outliers: drop the outlier pairs (see ``outlier_factor``) and solve again.
        outlier_factor: a pair is an outlier above this multiple of the median pair RMS...
        outlier_floor_px: ...and above this RMS (pixels), so that near-perfect sets (a
            synthetic board at 0.03 px) do not name pairs at 0.1 px.
        baseline_range_m: plausible baselines (metres); outside is refused.
        check_board_size: ask OpenCV's SB detector for the full chessboard size.
        bootstrap: resample the pairs this many times and store, per parameter, the larger
            of the bootstrap and the Jacobian standard deviation (0: Jacobian only).
        max_rms_px: an RMS above this (pixels) is warned about.
        seed: of the bootstrap.
    """

    drop_outliers: bool = False
    outlier_factor: float = 3.0
    outlier_floor_px: float = 0.1
    baseline_range_m: tuple[float, float] = (0.01, 2.0)
    check_board_size: bool = True
    bootstrap: int = 0
    max_rms_px: float = 1.0
    seed: int = 0


@dataclass(frozen=True)
class CalibrationResult:
    """The calibration, its RMS reprojection error (px), per-pair errors and rejections.

    Attributes:
        stereo: the calibration, with its ``uncertainty`` block filled.
        rms_px: RMS reprojection error of the joint solve (pixels, per point).
        per_pair_px: ``(name, RMS px)`` of every pair used in the final solve.
        rejected: ``(name, reason)`` of every pair not used (not found, dropped, ...).
        detectors: per pair used, the detectors that found the target (left, right).
        problems: what the checks found; ``refused`` those that forbid writing.
        dropped: pairs dropped as outliers (``CalibrateOptions.drop_outliers``).
    """

    stereo: StereoCalibration
    rms_px: float
    per_pair_px: list[tuple[str, float]]
    rejected: list[tuple[str, str]]
    detectors: dict[str, tuple[str, str]] = field(default_factory=dict)
    problems: list[CalibrationProblem] = field(default_factory=list)
    dropped: list[str] = field(default_factory=list)

    @property
    def refused(self) -> list[CalibrationProblem]:
        """The problems that forbid writing this calibration."""
        return [p for p in self.problems if p.refuse]


@dataclass(frozen=True)
class _Used:
    name: str
    left: np.ndarray
    right: np.ndarray
    detectors: tuple[str, str]


def _orient(left: np.ndarray, right: np.ndarray, spec: TargetSpec) -> np.ndarray:
    """The right corners in the left's order: a chessboard's grid found turned by 180° in one
    image (a different detector, a board nearly square to the view) is reversed back."""
    if spec.kind != "chessboard":
        return right
    if np.dot(left[-1] - left[0], right[-1] - right[0]) < 0:
        return right[::-1].copy()
    return right


def _detect_pairs(pairs, spec: TargetSpec):
    used: list[_Used] = []
    rejected: list[tuple[str, str]] = []
    unfound: list[np.ndarray] = []
    size = None
    for name, left, right in pairs:
        if left.shape[:2] != right.shape[:2]:
            (hl, wl), (hr, wr) = left.shape[:2], right.shape[:2]
            rejected.append((name, f"left {wl}x{hl} and right {wr}x{hr} differ in size"))
            continue
        if size is not None and (left.shape[1], left.shape[0]) != size:
            w, h = left.shape[1], left.shape[0]
            rejected.append((name, f"image size {w}x{h} differs from {size[0]}x{size[1]}"))
            continue
        size = (left.shape[1], left.shape[0])
        dl = find_target(left, spec)
        dr = find_target(right, spec) if dl.points is not None else None
        if dl.points is None or dr is None or dr.points is None:
            why = f"{dl.reason} (left)" if dl.points is None else f"{dr.reason} (right)"
            rejected.append((name, why))
            unfound.append(left if dl.points is None else right)
            continue
        pr = _orient(dl.points, dr.points, spec)
        used.append(
            _Used(
                name,
                dl.points.astype(np.float32),
                pr.astype(np.float32),
                (dl.detector, dr.detector),
            )
        )
    return used, rejected, size, unfound


@dataclass(frozen=True)
class _Solution:
    stereo: StereoCalibration
    rms_px: float
    per_view_px: np.ndarray  # (n, 2) left, right RMS
    rvecs: list[np.ndarray]
    tvecs: list[np.ndarray]


def _solve(used: list[_Used], spec: TargetSpec, size: tuple[int, int]) -> _Solution:
    obj = [spec.object_points().astype(np.float32)] * len(used)
    img_l = [u.left for u in used]
    img_r = [u.right for u in used]
    flags = cv2.CALIB_FIX_K3
    _, K1, d1, _, _ = cv2.calibrateCamera(obj, img_l, size, None, None, flags=flags)
    _, K2, d2, _, _ = cv2.calibrateCamera(obj, img_r, size, None, None, flags=flags)
    n = len(used)
    rms, K1, d1, K2, d2, R, T, _, _, rvecs, tvecs, errs = cv2.stereoCalibrateExtended(
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
        criteria=_CRITERIA,
    )
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
    return _Solution(
        stereo=stereo,
        rms_px=float(rms),
        per_view_px=np.asarray(errs, dtype=np.float64).reshape(n, 2),
        rvecs=[np.asarray(r, np.float64).reshape(3) for r in rvecs],
        tvecs=[np.asarray(t, np.float64).reshape(3) for t in tvecs],
    )


def _bootstrap_std(used, spec, size, sol: _Solution, n_boot: int, seed: int) -> np.ndarray:
    """Std over ``n_boot`` resamplings (with replacement) of the pairs of
    ``[fxL fyL cxL cyL k1L k2L p1L p2L, same right, rvec(3), T(3)]``."""
    st = sol.stereo
    obj = spec.object_points().astype(np.float32)
    rng = np.random.default_rng(seed)
    n = len(used)
    rows = []
    for _ in range(n_boot):
        idx = rng.integers(0, n, n)
        if len(set(idx.tolist())) < MIN_PAIRS:
            continue
        out = cv2.stereoCalibrate(
            [obj] * n,
            [used[i].left for i in idx],
            [used[i].right for i in idx],
            st.K_left.copy(),
            st.dist_left.copy(),
            st.K_right.copy(),
            st.dist_right.copy(),
            size,
            flags=cv2.CALIB_USE_INTRINSIC_GUESS | cv2.CALIB_FIX_K3,
            criteria=_CRITERIA,
        )
        _, K1, d1, K2, d2, R, T = out[:7]
        cams = [
            [K[0, 0], K[1, 1], K[0, 2], K[1, 2], *np.ravel(d)[:4]] for K, d in ((K1, d1), (K2, d2))
        ]
        rows.append([*cams[0], *cams[1], *cv2.Rodrigues(R)[0].ravel(), *np.ravel(T)])
    if len(rows) < 2:  # nothing to learn from: the Jacobian figures stand
        return np.zeros(22)
    return np.std(np.asarray(rows), axis=0, ddof=1)


def _uncertainty(used, spec, size, sol: _Solution, opts: CalibrateOptions):
    st = sol.stereo
    obj = spec.object_points()
    cov = stereo_covariance(
        obj,
        [u.left for u in used],
        [u.right for u in used],
        Camera(st.K_left, st.dist_left),
        Camera(st.K_right, st.dist_right),
        st.R,
        st.T,
        sol.rvecs,
        sol.tvecs,
    )
    KL, dL = cov.intrinsics_std("left")
    KR, dR = cov.intrinsics_std("right")
    rv, tv = cov.extrinsics_std()
    method = "jacobian"
    if opts.bootstrap > 1:
        b = _bootstrap_std(used, spec, size, sol, opts.bootstrap, opts.seed)
        KL, KR = np.maximum(KL, b[0:4]), np.maximum(KR, b[8:12])
        dL[:4], dR[:4] = np.maximum(dL[:4], b[4:8]), np.maximum(dR[:4], b[12:16])
        rv, tv = np.maximum(rv, b[16:19]), np.maximum(tv, b[19:22])
        method = f"max(jacobian, bootstrap over pairs x{opts.bootstrap})"
    return CalibrationUncertainty(
        K_std_left_px=KL,
        dist_std_left=dL,
        K_std_right_px=KR,
        dist_std_right=dR,
        rvec_std_rad=rv,
        T_std_m=tv,
        rms_px=sol.rms_px,
        per_view_rms_px=sol.per_view_px,
        method=method,
    )


def calibrate_stereo(
    pairs: Iterable[tuple[str, np.ndarray, np.ndarray]],
    spec: TargetSpec,
    options: CalibrateOptions | None = None,
) -> CalibrationResult:
    """Calibrate from ``(name, left, right)`` gray image pairs of ``spec``.

    Raises :class:`CalibrationTargetError` when fewer than :data:`MIN_PAIRS` pairs are usable
    (with a hint when OpenCV sees a board of another size). Every other problem is returned in
    :attr:`CalibrationResult.problems`; check :attr:`CalibrationResult.refused` before saving.
    """
    opts = options or CalibrateOptions()
    pairs = list(pairs)
    used, rejected, size, unfound = _detect_pairs(pairs, spec)
    if len(used) < MIN_PAIRS:
        hint = checks.size_hint(unfound, spec) if opts.check_board_size else ""
        raise CalibrationTargetError(
            f"only {len(used)} usable image pairs, at least {MIN_PAIRS} needed"
            + (f"; {hint}" if hint else ""),
            rejected,
        )
    problems = checks.check_pitch(spec)
    if opts.check_board_size:
        names = {u.name for u in used}
        problems += checks.check_board_size([p[1] for p in pairs if p[0] in names], spec)
    sol = _solve(used, spec, size)
    per_pair = _per_pair(used, sol)
    dropped: list[str] = []
    outliers = checks.find_outliers(per_pair, opts.outlier_factor, opts.outlier_floor_px)
    if outliers and opts.drop_outliers and len(used) - len(outliers) >= MIN_PAIRS:
        problems.append(checks.outlier_problem(per_pair, outliers, opts.outlier_factor, True))
        dropped = outliers
        rejected = rejected + [(n, "dropped: reprojection outlier") for n in outliers]
        used = [u for u in used if u.name not in outliers]
        sol = _solve(used, spec, size)
        per_pair = _per_pair(used, sol)
    elif outliers:
        problems.append(checks.outlier_problem(per_pair, outliers, opts.outlier_factor, False))
    if sol.rms_px > opts.max_rms_px:
        problems.append(
            CalibrationProblem(
                "rms",
                f"RMS reprojection error {sol.rms_px:.2f} px is above {opts.max_rms_px:g} px: "
                "check the board size, focus and that the board was still",
                refuse=False,
            )
        )
    problems += checks.check_baseline(sol.stereo, spec, opts.baseline_range_m)
    stereo = replace(sol.stereo, uncertainty=_uncertainty(used, spec, size, sol, opts))
    for p in problems:
        log.info("calibration: %s", p.message)
    return CalibrationResult(
        stereo=stereo,
        rms_px=sol.rms_px,
        per_pair_px=per_pair,
        rejected=rejected,
        detectors={u.name: u.detectors for u in used},
        problems=problems,
        dropped=dropped,
    )


def calibrate_points(
    left_px: list[np.ndarray],
    right_px: list[np.ndarray],
    spec: TargetSpec,
    image_size: tuple[int, int],
    options: CalibrateOptions | None = None,
) -> StereoCalibration:
    """The joint solve and its uncertainty from detected features (per view (N, 2) pixels in
    ``spec.object_points()`` order), without detection or checks (for simulations)."""
    opts = options or CalibrateOptions()
    used = [
        _Used(f"view{i}", np.asarray(a, np.float32), np.asarray(b, np.float32), ("", ""))
        for i, (a, b) in enumerate(zip(left_px, right_px, strict=True))
    ]
    sol = _solve(used, spec, image_size)
    return replace(sol.stereo, uncertainty=_uncertainty(used, spec, image_size, sol, opts))


def _per_pair(used: list[_Used], sol: _Solution) -> list[tuple[str, float]]:
    return [
        (u.name, float(np.sqrt(0.5 * (e[0] ** 2 + e[1] ** 2))))
        for u, e in zip(used, sol.per_view_px, strict=True)
    ]
