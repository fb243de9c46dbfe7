"""Do the calibration's predicted standard deviations match the spread over repeated boards?

Two Monte Carlo checks against a known truth (a wide-angle 640×480 head, f 520 px, 90 mm
baseline, a 9×6 board of 25 mm squares at 0.5–0.8 m):

1. **Feature noise**: the exact corner positions plus Gaussian noise (σ px), solved by
   :func:`measure.stereo_calibrate.calibrate_points`; the Jacobian prediction
   (:mod:`measure.calibration_covariance`) should equal the observed spread (ratio ≈ 1).
2. **Rendered boards**: new views for every seed, rendered (``measure.synth.render_target_pair``:
   blur, noise, vignetting) and detected by OpenCV, so the corner errors are the renderer's and
   the detector's, partly systematic, not iid Gaussian; the check is the RMS error against the
   truth over the seeds, against the Jacobian prediction and against the kept value (the larger
   of the Jacobian and the bootstrap over pairs, ``CalibrateOptions.bootstrap``).

The ratio ``observed / predicted`` per parameter is printed with the mean bias against the
truth (feature noise: the spread over seeds; rendered boards: the RMS error against the
truth). Usage: ``.venv/bin/python benchmarks/calibration_uncertainty.py [--seeds N]``.
"""

from __future__ import annotations

import argparse
import time

import cv2
import numpy as np

from measure.calibration import StereoCalibration
from measure.stereo_calibrate import CalibrateOptions, calibrate_points, calibrate_stereo
from measure.synth.targets import render_target_pair
from measure.target import TargetSpec

SPEC = TargetSpec("chessboard", 9, 6, 0.025)
NAMES = ("fx left px", "cx right px", "k1 left", "Tx mm", "Ty mm", "Tz mm", "rx mrad", "ry mrad")
SCALE = np.array([1, 1, 1, 1e3, 1e3, 1e3, 1e3, 1e3])


def wide_head() -> StereoCalibration:
    """The truth of both checks."""
    K = np.array([[520.0, 0, 318], [0, 522.0, 242], [0, 0, 1]])
    return StereoCalibration(
        (640, 480),
        K,
        np.array([-0.25, 0.1, 0.001, -0.0005, 0.0]),
        K * [[1.01], [1.01], [1]],
        np.array([-0.22, 0.08, 0, 0, 0.0]),
        cv2.Rodrigues(np.array([0.01, -0.03, 0.005]))[0],
        np.array([-0.09, 0.001, 0.002]),
    )


def views(st: StereoCalibration, n: int, seed: int = 3) -> list[np.ndarray]:
    """``n`` plate poses ``T_left_plate`` with the whole board inside both images."""
    obj = SPEC.object_points()
    rng = np.random.default_rng(seed)
    out = []
    while len(out) < n:
        R = cv2.Rodrigues(rng.uniform(-0.6, 0.6, 3) * np.array([1, 1, 0.5]))[0]
        c = np.array([*obj[:, :2].mean(axis=0), 0.0])
        T = np.eye(4)
        T[:3, :3] = R
        T[:3, 3] = np.array([*rng.uniform(-0.1, 0.1, 2), rng.uniform(0.5, 0.8)]) - R @ c
        X = (R @ obj.T).T + T[:3, 3]
        ok = True
        for side in ("left", "right"):
            p = st.project(X, side)
            ok &= bool(p.min() > 30 and (p < [610, 450]).all())
        if ok:
            out.append(T)
    return out


def _params(c: StereoCalibration) -> list[float]:
    return [
        c.K_left[0, 0],
        c.K_right[0, 2],
        c.dist_left[0],
        *c.T,
        *cv2.Rodrigues(c.R)[0].ravel()[:2],
    ]


def _stds(c: StereoCalibration) -> list[float]:
    u = c.uncertainty
    return [
        u.K_std_left_px[0],
        u.K_std_right_px[2],
        u.dist_std_left[0],
        *u.T_std_m,
        *u.rvec_std_rad[:2],
    ]


def _table(title: str, truth, est, pred, boot=None) -> None:
    est, pred = np.asarray(est) * SCALE, np.asarray(pred) * SCALE
    err = est - np.asarray(truth) * SCALE
    obs = np.sqrt(np.mean(err**2, axis=0)) if boot is not None else est.std(axis=0, ddof=1)
    print(f"\n{title}")
    head = f"{'parameter':<12} {'bias':>9} {'observed':>9} {'Jacobian':>9} {'ratio':>6}"
    print(head + (f" {'kept*':>9} {'ratio':>6}" if boot is not None else ""))
    bias = err.mean(axis=0)
    for k, name in enumerate(NAMES):
        line = f"{name:<12} {bias[k]:+9.4f} {obs[k]:9.4f} {pred[:, k].mean():9.4f} "
        line += f"{obs[k] / pred[:, k].mean():6.2f}"
        if boot is not None:
            b = np.asarray(boot)[:, k] * SCALE[k]
            line += f" {b.mean():9.4f} {obs[k] / b.mean():6.2f}"
        print(line)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=40)
    ap.add_argument("--views", type=int, default=10)
    args = ap.parse_args()
    st = wide_head()
    poses = views(st, args.views)
    obj = SPEC.object_points()
    truth = _params(st)
    t0 = time.process_time()
    for sigma in (0.1, 0.3):
        est, pred = [], []
        for seed in range(args.seeds):
            rng = np.random.default_rng(100 + seed)
            L, R = [], []
            for T in poses:
                X = (T[:3, :3] @ obj.T).T + T[:3, 3]
                L.append(st.project(X, "left") + rng.normal(0, sigma, (len(obj), 2)))
                R.append(st.project(X, "right") + rng.normal(0, sigma, (len(obj), 2)))
            c = calibrate_points(L, R, SPEC, st.image_size)
            est.append(_params(c))
            pred.append(_stds(c))
        _table(
            f"feature noise σ = {sigma} px, {args.views} views, {args.seeds} seeds "
            "(ratio = observed / predicted)",
            truth,
            est,
            pred,
        )
    n_render = max(args.seeds // 4, 6)
    est, pred, boot = [], [], []
    for seed in range(n_render):
        pairs = []
        for k, T in enumerate(views(st, args.views, seed=50 + seed)):
            r = render_target_pair(st, SPEC, T, seed=1000 * seed + k, noise_dn=2.0)
            pairs.append((f"v{k}", r.left, r.right))
        res = calibrate_stereo(pairs, SPEC, CalibrateOptions(bootstrap=50, seed=seed))
        jac = calibrate_stereo(pairs, SPEC, CalibrateOptions(check_board_size=False))
        est.append(_params(res.stereo))
        pred.append(_stds(jac.stereo))
        boot.append(_stds(res.stereo))
    _table(
        f"rendered boards (blur 0.7 px, noise 2 DN), detected by OpenCV, {args.views} new "
        f"views per seed, {n_render} seeds; observed = RMS error against the truth; "
        "kept* = max(Jacobian, bootstrap x50)",
        truth,
        est,
        pred,
        boot,
    )
    print(f"\n({time.process_time() - t0:.0f} s cpu)")


if __name__ == "__main__":
    main()
