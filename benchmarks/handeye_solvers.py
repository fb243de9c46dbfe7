"""Hand-eye solvers on simulated data with a known truth: our adjustment against plain OpenCV.

For each seed, a truth is drawn (:func:`cell.calibration.estimate.synthetic.example_truth`:
the standard toed-in head on an ABB IRB 1600, D-H errors of 0.3 mm and 0.02 deg, the head 1 mm and
0.3 deg off its drawing) and ``--views`` views of the target are simulated with ``--noise`` px of
corner noise. Two scenarios:

- ``exact flange``: the arm has no D-H errors, every method gets the true flange poses (the
  adjustment too: no kinematic terms);
- ``D-H errors``: OpenCV gets the flange poses of the nominal kinematics (all it can have); the
  adjustment estimates the D-H errors from the joints.

A third scenario adds the arm's pose scatter (20 um and 40 urad per axis at each view, which
the data do not report). Per method: hand-eye error (mm, deg) against the truth (in the
adjustment's gauge: the redundant joint-6 terms folded into the hand-eye), the camera's pose
relative to the target at 200 random poses near the views (mm, deg RMS; free of any gauge)
and the time (ms). OpenCV's
hand-eye methods take the per-view PnP poses of the left camera (``cv2.solvePnP``, IPPE then
LM); the adjustment uses both cameras.

    python benchmarks/handeye_solvers.py --seeds 5 --views 15
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from scipy.spatial.transform import Rotation

from cell.calibration.estimate import (
    example_truth,
    flange_poses,
    hand_eye_candidates,
    parameter_errors,
    pose_error,
    reference_joints,
    simulate,
    solve_calibration,
    solve_pnp,
    truth_in_gauge,
    view_joints,
)
from robots.calibration import fk_with_errors


def _seen(tr, n: int, seed: int) -> np.ndarray:
    Q = view_joints(tr, 4 * n, (0.2, 0.32), reference_joints(tr), seed=seed)
    obs = simulate(tr, Q, 0.0)
    ok = [
        i
        for i, v in enumerate(obs.views)
        if v.corners_left_px is not None and v.corners_right_px is not None
    ]
    return Q[ok[:n]]


def _camera_error(tr, Q_test, T_bt_est, X_est, Y_est) -> tuple[float, float]:
    """RMS position (m) and angle (rad) of T_target_camera predicted vs true at test poses."""
    T_true = (
        np.linalg.inv(tr.truth.T_base_target)
        @ fk_with_errors(tr.dh, tr.truth.delta, Q_test)
        @ tr.truth.T_tool0_camera
    )
    T_est = np.linalg.inv(Y_est) @ T_bt_est @ X_est
    dp = np.linalg.norm(T_est[:, :3, 3] - T_true[:, :3, 3], axis=1)
    da = (
        Rotation.from_matrix(T_est[:, :3, :3]) * Rotation.from_matrix(T_true[:, :3, :3]).inv()
    ).magnitude()
    return float(np.sqrt(np.mean(dp**2))), float(np.sqrt(np.mean(da**2)))


def run_seed(
    seed: int,
    n_views: int,
    noise_px: float,
    kinematic: bool,
    scatter: tuple[float, float] = (0.0, 0.0),
) -> dict[str, tuple[float, ...]]:
    """method -> (hand-eye mm, hand-eye deg, camera mm RMS, camera deg RMS, time ms, share of
    the hand-eye's six components within 2 stated sigma (the adjustment; NaN for OpenCV))."""
    tr = example_truth(seed, kinematic=kinematic)
    Q = _seen(tr, n_views, seed + 1000)
    obs = simulate(
        tr,
        Q,
        noise_px,
        seed=seed + 2000,
        with_joints=kinematic,
        flange_sigma_m=scatter[0],
        flange_sigma_rad=scatter[1],
    )
    rng = np.random.default_rng(seed)
    Q_test = Q[rng.integers(0, len(Q), 200)] + rng.normal(0, 0.05, (200, 6))
    gauge = truth_in_gauge(tr)
    out = {}
    t0 = time.perf_counter()
    T_bt_nominal = flange_poses(obs, tr.dh if kinematic else None, np.zeros(24))
    T_ct, idx = solve_pnp(obs)
    t_pnp = time.perf_counter() - t0
    for cand in hand_eye_candidates(T_bt_nominal[list(idx)], T_ct):
        if not np.isfinite(cand.spread_m):
            out[f"opencv {cand.method}"] = (np.nan,) * 6
            continue
        dp, da = pose_error(cand.T_tool0_camera, gauge.T_tool0_camera)
        cp, ca = _camera_error(
            tr, Q_test, flange_poses_q(tr, Q_test, None), cand.T_tool0_camera, cand.T_base_target
        )
        out[f"opencv {cand.method}"] = (
            dp * 1e3,
            np.rad2deg(da),
            cp * 1e3,
            np.rad2deg(ca),
            (t_pnp + cand.time_s) * 1e3,
            np.nan,
        )
    res = solve_calibration(obs, tr.dh if kinematic else None)
    cal = res.calibration
    dp, da = pose_error(cal.T_tool0_camera.T, gauge.T_tool0_camera)
    cp, ca = _camera_error(
        tr, Q_test, flange_poses_q(tr, Q_test, cal.delta), cal.T_tool0_camera.T, cal.T_base_target.T
    )
    err = parameter_errors(cal, gauge)
    he = [n for n in cal.parameter_names if n.startswith("T_tool0_camera.")]
    within = np.mean([abs(err[n]) < 2 * cal.sigma(n) for n in he])
    out["adjustment"] = (
        dp * 1e3,
        np.rad2deg(da),
        cp * 1e3,
        np.rad2deg(ca),
        res.timings["total_s"] * 1e3,
        within,
    )
    return out


def flange_poses_q(tr, Q, delta) -> np.ndarray:
    """Flange poses of joints Q with the D-H errors ``delta`` (nominal when None)."""
    return fk_with_errors(tr.dh, np.zeros(24) if delta is None else delta, Q)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seeds", type=int, default=5)
    ap.add_argument("--views", type=int, default=15)
    ap.add_argument("--noise", type=float, default=0.1, help="corner noise (px, one sigma)")
    args = ap.parse_args()
    scenarios = (
        (False, (0.0, 0.0), "exact flange poses"),
        (True, (0.0, 0.0), "D-H errors (OpenCV: nominal kinematics)"),
        (True, (20e-6, 40e-6), "D-H errors and 20 um / 40 urad flange scatter per view"),
    )
    for kinematic, scatter, title in scenarios:
        rows: dict[str, list] = {}
        for s in range(args.seeds):
            for k, v in run_seed(s, args.views, args.noise, kinematic, scatter).items():
                rows.setdefault(k, []).append(v)
        print(f"\n{title}: {args.seeds} seeds, {args.views} views, {args.noise} px noise")
        print(
            f"{'method':<20} {'hand-eye mm':>12} {'deg':>8} {'camera mm':>10} {'deg':>8} "
            f"{'time ms':>8}  (medians; worst hand-eye mm; hand-eye within 2 sigma)"
        )
        for k, v in rows.items():
            a = np.array(v)
            med = np.array([np.nanmedian(c) if np.isfinite(c).any() else np.nan for c in a.T])
            print(
                f"{k:<20} {med[0]:12.4f} {med[1]:8.4f} {med[2]:10.4f} {med[3]:8.4f} "
                f"{med[4]:8.1f}  worst {np.nanmax(a[:, 0]):.4f}"
                + ("" if np.all(np.isnan(a[:, 5])) else f"  {np.nanmean(a[:, 5]) * 100:.0f} %")
            )


if __name__ == "__main__":
    main()
