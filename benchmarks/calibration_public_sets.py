"""Stereo calibration on public real chessboard sets, against OpenCV's own sample pipeline and
published results; the user mistakes (wrong board size, millimetre pitch) tried on them.

The images are not in the repository (their licences are not ours); fetch them into a scratch
folder and pass the folders:

- ``--opencv DIR``: OpenCV's stereo sample (``samples/data/left01.jpg`` … ``right14.jpg``,
  13 pairs, 640×480, 9×6 inner corners; the square side is not published, 25 mm is assumed, so
  only the baseline *in squares* is comparable). Debian's ``opencv-doc`` package ships it in
  ``/usr/share/doc/opencv-doc/examples/data``.
- ``--ximea DIR``: a XIMEA 640×512 stereo pair set on GitHub (``Barry-Liang/stereoCalibrate``,
  ``left01.jpg`` … ``right25.jpg``, 6×9 inner corners, 24 mm squares) with its published result
  (``intrinsics.yml``/``extrinsics.yml`` of the repository: f = 518.05 px, one focal length for
  both cameras, T = (91.204, −2.647, 12.201) mm).

Usage: ``.venv/bin/python benchmarks/calibration_public_sets.py --opencv DIR --ximea DIR``
"""

from __future__ import annotations

import argparse
import glob
import os
import time
from pathlib import Path

import cv2
import numpy as np

from measure.errors import CalibrationTargetError
from measure.stereo_calibrate import CalibrateOptions, calibrate_stereo
from measure.target import TargetSpec

_CLASSIC = cv2.CALIB_CB_ADAPTIVE_THRESH | cv2.CALIB_CB_NORMALIZE_IMAGE
_SB = cv2.CALIB_CB_NORMALIZE_IMAGE | cv2.CALIB_CB_EXHAUSTIVE | cv2.CALIB_CB_ACCURACY

#: published result of the XIMEA set (its repository's intrinsics.yml / extrinsics.yml)
XIMEA_PUBLISHED = {
    "f_px": (518.05160946433762, 518.05160946433762),
    "T_m": np.array([91.204379214855877, -2.6467940379585433, 12.201294785624963]) * 1e-3,
    "R": np.array(
        [
            [0.99767721547053001, 0.036183684149507275, -0.057714077419103865],
            [-0.034696972694561859, 0.99904495071183330, 0.026557608006434079],
            [0.058619909730418793, -0.024493416637114532, 0.99797984885699886],
        ]
    ),
}


def _pairs(folder: str) -> list[tuple[str, np.ndarray, np.ndarray]]:
    out = []
    for lp in sorted(glob.glob(os.path.join(folder, "left[0-9]*.jpg"))):
        rp = lp.replace("left", "right")
        if os.path.exists(rp):
            name = f"{Path(lp).stem}/{Path(rp).stem}"
            out.append((name, cv2.imread(lp, cv2.IMREAD_GRAYSCALE), cv2.imread(rp, 0)))
    return out


def _found(img: np.ndarray, size: tuple[int, int]) -> dict[str, bool]:
    return {
        "fast": cv2.findChessboardCorners(img, size, flags=_CLASSIC | cv2.CALIB_CB_FAST_CHECK)[0],
        "plain": cv2.findChessboardCorners(img, size, flags=_CLASSIC)[0],
        "sb": cv2.findChessboardCornersSB(img, size, flags=_SB)[0],
    }


def _classic_corners(pairs, size: tuple[int, int], pitch: float, eps: float):
    """Board points and left/right corners of every pair both cameras see, as OpenCV's samples
    find them: classic detector (no fast check), cornerSubPix 11×11 to ``eps`` px."""
    crit = (cv2.TERM_CRITERIA_COUNT | cv2.TERM_CRITERIA_EPS, 30, eps)
    obj1 = np.zeros((size[0] * size[1], 3), np.float32)
    obj1[:, :2] = np.mgrid[0 : size[0], 0 : size[1]].T.reshape(-1, 2) * pitch
    L, R = [], []
    for _, left, right in pairs:
        got = []
        for img in (left, right):
            ok, c = cv2.findChessboardCorners(img, size, flags=_CLASSIC)
            got.append(cv2.cornerSubPix(img, c, (11, 11), (-1, -1), crit) if ok else None)
        if all(g is not None for g in got):
            L.append(got[0])
            R.append(got[1])
    obj = [obj1] * len(L)
    wh = pairs[0][1].shape[::-1]
    return obj, L, R, wh


def _opencv_sample(pairs, size: tuple[int, int], pitch: float):
    """OpenCV's samples/cpp/stereo_calib.cpp: classic detector, cornerSubPix 11×11, one
    stereoCalibrate with the sample's flags (same focal length, rational model k4–k6 fixed)."""
    obj, L, R, wh = _classic_corners(pairs, size, pitch, 0.01)
    K1 = cv2.initCameraMatrix2D(obj, L, wh, 0)
    K2 = cv2.initCameraMatrix2D(obj, R, wh, 0)
    flags = (
        cv2.CALIB_FIX_ASPECT_RATIO
        | cv2.CALIB_ZERO_TANGENT_DIST
        | cv2.CALIB_USE_INTRINSIC_GUESS
        | cv2.CALIB_SAME_FOCAL_LENGTH
        | cv2.CALIB_RATIONAL_MODEL
        | cv2.CALIB_FIX_K3
        | cv2.CALIB_FIX_K4
        | cv2.CALIB_FIX_K5
    )
    rms, K1, _, K2, _, Rm, T, _, _ = cv2.stereoCalibrate(
        obj,
        L,
        R,
        K1,
        np.zeros(8),
        K2,
        np.zeros(8),
        wh,
        flags=flags,
        criteria=(cv2.TERM_CRITERIA_COUNT | cv2.TERM_CRITERIA_EPS, 100, 1e-5),
    )
    return {"f_px": (K1[0, 0], K2[0, 0]), "T_m": T.ravel(), "R": Rm, "rms": rms, "n": len(L)}


def _opencv_plain(pairs, size: tuple[int, int], pitch: float):
    """OpenCV's Python calibration tutorial, per camera then for the pair: classic detector
    (no fast check), cornerSubPix 11×11, ``calibrateCamera`` with its default model (k3 free),
    ``stereoCalibrate`` with its default ``CALIB_FIX_INTRINSIC``."""
    obj, L, R, wh = _classic_corners(pairs, size, pitch, 0.001)
    _, K1, d1, _, _ = cv2.calibrateCamera(obj, L, wh, None, None)
    _, K2, d2, _, _ = cv2.calibrateCamera(obj, R, wh, None, None)
    rms, K1, _, K2, _, Rm, T, _, _ = cv2.stereoCalibrate(obj, L, R, K1, d1, K2, d2, wh)
    return {"f_px": (K1[0, 0], K2[0, 0]), "T_m": T.ravel(), "R": Rm, "rms": rms, "n": len(L)}


def _rot_deg(A: np.ndarray, B: np.ndarray) -> float:
    return float(np.degrees(np.arccos(np.clip((np.trace(A @ B.T) - 1) / 2, -1, 1))))


def _compare(label: str, ours, ref) -> str:
    st = ours.stereo
    df = [
        100 * (st.K_left[0, 0] / ref["f_px"][0] - 1),
        100 * (st.K_right[0, 0] / ref["f_px"][1] - 1),
    ]
    db = 100 * (st.baseline_m / np.linalg.norm(ref["T_m"]) - 1)
    return (
        f"  vs {label:<22} f {df[0]:+.2f} % / {df[1]:+.2f} %, baseline {db:+.3f} %, "
        f"rotation {_rot_deg(st.R, ref['R']):.3f}° apart"
    )


def run_set(name: str, folder: str, cols: int, rows: int, pitch: float, published) -> None:
    pairs = _pairs(folder)
    spec = TargetSpec("chessboard", cols, rows, pitch)
    print(f"\n== {name}: {len(pairs)} pairs in {folder}, {cols}x{rows} corners, {pitch} m squares")
    counts = {"fast": 0, "plain": 0, "sb": 0, "plain or sb": 0}
    either_pairs = []
    for pname, left, right in pairs:
        f = [_found(img, spec.pattern_size) for img in (left, right)]
        for k in ("fast", "plain", "sb"):
            counts[k] += f[0][k] + f[1][k]
        ok = [d["plain"] or d["sb"] for d in f]
        counts["plain or sb"] += sum(ok)
        if all(ok):
            either_pairs.append(pname)
    print(
        f"boards found in {2 * len(pairs)} images: fast check {counts['fast']}, plain "
        f"{counts['plain']}, SB {counts['sb']}, plain or SB {counts['plain or sb']}"
    )
    t = time.process_time()
    res = calibrate_stereo(pairs, spec, CalibrateOptions(bootstrap=100))
    cpu = time.process_time() - t
    used = dict(res.per_pair_px)
    missed = [p for p in either_pairs if p not in used]
    print(
        f"holecell uses {len(used)} pairs; pairs with the board found by plain or SB in both "
        f"images: {len(either_pairs)}; missed: {missed or 'none'} ({cpu:.1f} s cpu)"
    )
    retried = {n: d for n, d in res.detectors.items() if d != ("fast", "fast")}
    print(f"found only on a retry: {retried or 'none'}")
    st, u = res.stereo, res.stereo.uncertainty
    print(
        f"holecell: RMS {res.rms_px:.3f} px, f {st.K_left[0, 0]:.2f} ± {u.K_std_left_px[0]:.2f} / "
        f"{st.K_right[0, 0]:.2f} ± {u.K_std_right_px[0]:.2f} px, baseline "
        f"{st.baseline_m * 1e3:.3f} mm ({st.baseline_m / pitch:.3f} squares), "
        f"T = {np.round(st.T * 1e3, 3).tolist()} mm ± {np.round(u.T_std_m * 1e3, 3).tolist()}"
    )
    for p in res.problems:
        print(f"  {'refused' if p.refuse else 'warning'}: {p.message}")
    jac = calibrate_stereo(pairs, spec, CalibrateOptions(bootstrap=0)).stereo.uncertainty
    print(
        "std, Jacobian vs kept (max with bootstrap x100): "
        f"fx {jac.K_std_left_px[0]:.2f} / {u.K_std_left_px[0]:.2f} px, "
        f"T {np.round(jac.T_std_m * 1e6, 0).tolist()} / "
        f"{np.round(u.T_std_m * 1e6, 0).tolist()} µm, "
        f"rvec {np.round(jac.rvec_std_rad * 1e3, 2).tolist()} / "
        f"{np.round(u.rvec_std_rad * 1e3, 2).tolist()} mrad"
    )
    for label, fn in (("plain OpenCV", _opencv_plain), ("OpenCV sample pipeline", _opencv_sample)):
        ref = fn(pairs, spec.pattern_size, pitch)
        print(
            f"{label}: {ref['n']} pairs, RMS {ref['rms']:.3f} px, f {ref['f_px'][0]:.2f} / "
            f"{ref['f_px'][1]:.2f} px, baseline {np.linalg.norm(ref['T_m']) * 1e3:.3f} mm"
        )
        print(_compare(label, res, ref))
    if published is not None:
        print(_compare("published result", res, published))
    if res.problems and any(p.kind == "outliers" for p in res.problems):
        drop = calibrate_stereo(pairs, spec, CalibrateOptions(drop_outliers=True))
        print(
            f"--drop-outliers: RMS {drop.rms_px:.3f} px over {len(drop.per_pair_px)} pairs, "
            f"baseline {drop.stereo.baseline_m * 1e3:.3f} mm"
        )
        if published is not None:
            print(_compare("published (dropped)", drop, published))
    for label, wrong in (
        (f"--cols {cols - 1}", TargetSpec("chessboard", cols - 1, rows, pitch)),
        (f"--rows {rows - 1}", TargetSpec("chessboard", cols, rows - 1, pitch)),
        (f"--pitch {pitch * 1e3:g}", TargetSpec("chessboard", cols, rows, pitch * 1e3)),
        (f"--cols {cols + 1}", TargetSpec("chessboard", cols + 1, rows, pitch)),
    ):
        try:
            r = calibrate_stereo(pairs, wrong)
        except CalibrationTargetError as exc:
            print(f"mistake {label:<11}: error: {str(exc).splitlines()[0]}")
            continue
        verdict = "refused" if r.refused else "WRITTEN"
        why = "; ".join(p.message[:110] for p in r.refused) or "no refusal"
        print(
            f"mistake {label:<11}: {verdict} (RMS {r.rms_px:.2f} px, {len(r.per_pair_px)} pairs, "
            f"baseline {r.stereo.baseline_m:.4g} m): {why}"
        )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--opencv", help="folder with OpenCV's left01.jpg … right14.jpg")
    ap.add_argument("--ximea", help="folder with the XIMEA set's left01.jpg … right25.jpg")
    args = ap.parse_args()
    if args.opencv:
        run_set("OpenCV stereo sample", args.opencv, 9, 6, 0.025, None)
    if args.ximea:
        run_set("XIMEA 640x512 set", args.ximea, 6, 9, 0.024, XIMEA_PUBLISHED)


if __name__ == "__main__":
    main()
