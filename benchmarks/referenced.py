"""Photogrammetric referencing on simulated truths: the survey's marker network and the holes
located against it, against the truth (docs/referencing.md).

For each seed a truth is drawn (:meth:`cell.sim.truth.CellTruth.drawn`: D-H, base, head mount,
part placement, the part as machined, the head's calibration error) and the markers' true
positions (:func:`cell.referencing.synthetic.draw_marker_truth`: 0.3 mm off nominal, the part's
markers moved with the part). The survey's views are taken from their planned poses with an arm
error (``--arm-mm``, ``--arm-deg``); each marker centre is the true centre through the TRUE head
plus ``--sigma-px`` of detector noise. The adjustment (GTSAM) is compared with the plain SciPy
reference and with the truth. Then each hole's stop: the hole rendered through the true head
and measured (:func:`measure.measure_hole`, the real pipeline), the stop located against the
surveyed markers (:func:`cell.referencing.resect`), the hole carried into the cell; the drawing's
datum frame built from the measured datum features and compared with the true one.

Figures (per seed): survey RMS / worst vs truth after a rigid fit, scale error (ppm), markers
within their stated 2 sigma; holes: datum-frame position error in the hole plane (RMS, worst),
truth within U, the position characteristics with U <= 1/4 of their zone; times.

    python benchmarks/referenced.py [--seeds 10] [--large] [--sigma-px 0.05] [--arm-x 1]
        [--sigma-floor-px 0.02]
"""

from __future__ import annotations

import argparse
import math
import time
from dataclasses import replace

import numpy as np

from cell.camera import cell_stereo
from cell.config import load_builtin_cell
from cell.gdt.evaluate import evaluate
from cell.gdt.montecarlo import McOptions
from cell.gdt.truth_check import coverage, true_evaluation
from cell.records.hole_result import HoleResult
from cell.referencing.layout import stop_pose
from cell.referencing.resection import resect
from cell.referencing.sigma import SIGMA_FLOOR_PX
from cell.referencing.survey.gauge import rigid_fit, to_gauge
from cell.referencing.survey.plan import survey_views
from cell.referencing.survey.problem import build_problem
from cell.referencing.survey.select import SelectOptions, select_cell_views
from cell.referencing.survey.solve_scipy import solve_scipy
from cell.referencing.survey.survey import SurveyOptions, survey
from cell.referencing.synthetic import draw_marker_truth, observe
from cell.sim.camera import true_head
from cell.sim.truth import CellTruth
from cell.sim.world import SimWorld, WorldOptions
from measure import MeasurementError, measure_hole
from measure.synth import render_hole_pair
from robots.transforms import invert, pose_to_matrix, so3_exp, so3_log


def _perturbed(T: np.ndarray, rng: np.random.Generator, mm: float, deg: float) -> np.ndarray:
    out = T.copy()
    out[:3, :3] = so3_exp(rng.normal(0.0, math.radians(deg), 3)) @ T[:3, :3]
    out[:3, 3] += rng.normal(0.0, mm * 1e-3, 3)
    return out


def _large(seed: int, cell) -> CellTruth:
    """The large-error truth: every geometric error three times the realistic draw's."""
    t = CellTruth.drawn(seed, cell)

    def grow(T: np.ndarray) -> np.ndarray:
        out = np.eye(4)
        out[:3, :3] = so3_exp(3 * so3_log(T[:3, :3]))
        out[:3, 3] = 3 * T[:3, 3]
        return out

    return replace(
        t,
        dh_errors=3 * t.dh_errors,
        base_error=grow(t.base_error),
        tcp_error=grow(t.tcp_error),
        part_placement_error=grow(t.part_placement_error),
    )


def run_seed(seed: int, args, cell, stereo) -> dict:
    truth = _large(seed, cell) if args.large else CellTruth.drawn(seed, cell)
    world = SimWorld(cell, WorldOptions(truth=truth))
    head = true_head(stereo, truth.calibration_sigma_scale, truth.seed)
    mt = draw_marker_truth(cell, seed, 3e-4, truth.part_placement_error)
    rng = np.random.default_rng([seed, 77])
    views = []
    planned = survey_views(cell, stereo)
    if args.min_views > 0:
        planned = select_cell_views(cell, stereo, planned, SelectOptions(min_views=args.min_views))
    for vid, T_plan in planned:
        T_true = _perturbed(T_plan, rng, args.arm_mm * args.arm_x, args.arm_deg * args.arm_x)
        views.append(observe(mt, head, T_true, vid, args.sigma_px, rng, T_plan))
    t0 = time.perf_counter()
    res = survey(
        cell,
        stereo,
        views,
        SurveyOptions(sigma_px=args.sigma_px, sigma_floor_px=args.sigma_floor_px),
    )
    t_survey = time.perf_counter() - t0
    out = {"seed": seed, "survey_s": t_survey, "views": res.n_views}
    # survey vs truth: the truth in the survey's gauge (its fixture markers fitted to nominal)
    rows = [mt.ids.index(m) for m in res.marker_ids]
    true_pts = mt.true[rows]
    T = rigid_fit(true_pts[mt.on_fixture[rows]], mt.nominal[rows][mt.on_fixture[rows]])
    true_g = true_pts @ T[:3, :3].T + T[:3, 3]
    e = res.positions_cell - true_g
    z = np.abs(e) / res.sigma_m()
    out["within_2s"] = float(np.mean(z < 2.0))  # per coordinate: 95.4 % for an honest sigma
    F = rigid_fit(res.positions_cell, true_pts)
    ef = np.linalg.norm(res.positions_cell @ F[:3, :3].T + F[:3, 3] - true_pts, axis=1)
    out["survey_rms_um"], out["survey_max_um"] = 1e6 * np.sqrt(np.mean(ef**2)), 1e6 * ef.max()
    d_est = np.linalg.norm(res.positions_cell[:, None] - res.positions_cell[None], axis=2)
    d_true = np.linalg.norm(true_pts[:, None] - true_pts[None], axis=2)
    out["scale_ppm"] = 1e6 * (np.sum(d_est * d_true) / np.sum(d_true**2) - 1.0)
    out["scale_sigma_ppm"] = res.scale_sigma_ppm
    if args.reference:
        kept = [v for v in views if v.view_id not in set(res.dropped_views)]
        ids = list(res.marker_ids)
        p = build_problem(
            kept,
            stereo,
            ids,
            mt.nominal[rows],
            [(b.from_, b.to, b.length_m, b.U_m) for b in cell.scale_bars],
            args.sigma_px,
        )
        t0 = time.perf_counter()
        s = solve_scipy(p)
        out["scipy_s"] = time.perf_counter() - t0
        g = to_gauge(s.points, None, mt.nominal[rows], mt.on_fixture[rows])
        out["scipy_vs_gtsam_um"] = 1e6 * np.abs(g.points - res.positions_cell).max()
    out.update(_holes(seed, args, cell, stereo, world, head, mt, res, rng))
    return out


def _holes(seed, args, cell, stereo, world, head, mt, res, rng) -> dict:
    T_cell_part = cell.T_cell_part()
    T_part_cell = invert(T_cell_part)
    w_net, v_net = np.linalg.eigh(0.5 * (res.covariance + res.covariance.T))
    L_net = v_net * np.sqrt(np.clip(w_net, 0.0, None))  # the network's error: L_net z
    results, t_res, fallback = [], [], 0
    measured_with = res.stereo or stereo  # the head as the survey self-calibrated it
    for i, h in enumerate(cell.part.holes):
        true = world.holes[h.id]
        T_plan = stop_pose(cell, stereo, h.id)
        T_true = _perturbed(T_plan, rng, args.arm_mm * args.arm_x, args.arm_deg * args.arm_x)
        T_left_cell = invert(T_true)
        c = T_left_cell[:3, :3] @ true.position_m + T_left_cell[:3, 3]
        n = T_left_cell[:3, :3] @ true.normal
        pair = render_hole_pair(head, c, n, true.diameter_m, seed=seed * 1000 + i)
        try:
            meas = measure_hole(
                pair.left,
                pair.right,
                measured_with,
                expected_diameter_m=h.diameter,
                expected_standoff_m=cell.tool.standoff_m,
            )
        except MeasurementError:
            continue
        view = observe(mt, head, T_true, h.id, args.sigma_px, rng, T_plan)
        t0 = time.thread_time()
        r = resect(
            view,
            measured_with,
            res.marker_ids,
            res.positions_cell,
            res.covariance,
            args.sigma_px,
            res.sigma_effective_px,
        )
        t_res.append(time.thread_time() - t0)
        if not r.ok:
            fallback += 1
            continue
        cov_fit = np.asarray(meas.cov_center_radius, float)[:3, :3]
        p_cell, cov_cell = r.point(meas.center_m, cov_fit)
        p_part = T_part_cell[:3, :3] @ p_cell + T_part_cell[:3, 3]
        R_pc = T_part_cell[:3, :3]
        cov_part = R_pc @ cov_cell @ R_pc.T
        # the components as a run stores them: the survey's error shared through its factor
        J = R_pc @ r.point_jacobian(meas.center_m)
        R_pl = R_pc @ r.T_cell_left[:3, :3]
        cols = np.asarray(r.marker_columns, np.int64)
        F = J @ r.marker_sensitivity @ L_net[(3 * cols[:, None] + np.arange(3)).ravel()]
        parts = {
            "circle_fit": R_pl @ cov_fit @ R_pl.T,
            "resection": J @ (r.covariance - r.covariance_markers) @ J.T,
            "survey_markers": J @ r.covariance_markers @ J.T,
        }
        if args.independent_markers:
            F = None
        results.append(
            HoleResult(
                hole_id=h.id,
                stop_index=i,
                status="ok",
                nominal_part_m=tuple(h.position),
                nominal_diameter_m=h.diameter,
                tolerance_m=h.tolerance,
                center_part_m=tuple(float(v) for v in p_part),
                normal_part=tuple(h.normal),
                diameter_m=float(meas.diameter_m),
                rms_m=0.0,
                U_diameter_m=float(2 * 2 * np.sqrt(max(meas.cov_center_radius[3][3], 0.0))),
                extra={
                    "cov_center_part_m2": cov_part.tolist(),
                    "cov_components_part_m2": {k: v.tolist() for k, v in parts.items()},
                    "R_part_left": R_pl.tolist(),
                }
                | ({} if F is None else {"survey_markers_factor_part": F.tolist()}),
            )
        )
    centres = {
        k: T_part_cell[:3, :3] @ h.position_m + T_part_cell[:3, 3] for k, h in world.holes.items()
    }
    truth = true_evaluation(cell, centres, {k: h.diameter_m for k, h in world.holes.items()})
    ev = evaluate(cell, results, McOptions(n_draws=400))
    out = {
        "stops": len(results),
        "fallback": fallback,
        "resect_ms": 1e3 * float(np.median(t_res)) if t_res else float("nan"),
    }
    if ev.placement is None or truth.placement is None:
        return out | {"hole_rms_um": float("nan"), "hole_max_um": float("nan")}

    # fixture -> part, measured DRF and true DRF
    Tm = invert(pose_to_matrix(**ev.placement["T_fixture_part"]))
    Tt = invert(pose_to_matrix(**truth.placement["T_fixture_part"]))
    errs = []
    for r in results:
        nrm = np.asarray(cell.part.holes[r.stop_index].normal, float)
        d = (Tm[:3, :3] @ np.array(r.center_part_m) + Tm[:3, 3]) - (
            Tt[:3, :3] @ centres[r.hole_id] + Tt[:3, 3]
        )
        errs.append(np.linalg.norm(d - (d @ nrm) * nrm))
    errs = np.array(errs)
    # the same holes after a best fit of all of them onto the truth (no datum frame)
    M = np.array([r.center_part_m for r in results])
    Tt_all = np.array([centres[r.hole_id] for r in results])
    N = np.array([cell.part.holes[r.stop_index].normal for r in results], float)
    B = rigid_fit(M, Tt_all)
    d = M @ B[:3, :3].T + B[:3, 3] - Tt_all
    bf = np.linalg.norm(d - np.sum(d * N, axis=1)[:, None] * N, axis=1)
    cov = coverage(ev.characteristics, truth)
    pos = [c for c in ev.characteristics if c["kind"] == "position" and c.get("U_m") is not None]
    ratio = [c["U_m"] / c["zone_diameter_m"] for c in pos]
    out.update(
        {
            "hole_rms_um": 1e6 * np.sqrt(np.mean(errs**2)),
            "hole_max_um": 1e6 * errs.max(),
            "bestfit_rms_um": 1e6 * np.sqrt(np.mean(bf**2)),
            "bestfit_max_um": 1e6 * bf.max(),
            "within_U": float(np.mean(cov.of_kind("position")))
            if cov.of_kind("position")
            else float("nan"),
            "gauge_4to1": sum(r <= 0.25 for r in ratio),
            "n_position": len(ratio),
            "U_median_um": 1e6 * float(np.median([c["U_m"] for c in pos])) if pos else float("nan"),
        }
    )
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seeds", type=int, default=10)
    ap.add_argument("--first-seed", type=int, default=0)
    ap.add_argument("--large", action="store_true", help="three times the realistic errors")
    ap.add_argument("--sigma-px", type=float, default=0.05, help="marker centre noise (px)")
    ap.add_argument(
        "--sigma-floor-px",
        type=float,
        default=SIGMA_FLOOR_PX,
        help="the smallest centre noise the covariances are stated at (px)",
    )
    ap.add_argument("--arm-mm", type=float, default=0.2, help="arm error of a view (mm, per axis)")
    ap.add_argument("--arm-deg", type=float, default=0.02, help="arm error of a view (deg)")
    ap.add_argument("--arm-x", type=float, default=1.0, help="multiply the arm's errors")
    ap.add_argument("--reference", action="store_true", help="also solve with SciPy (slow)")
    ap.add_argument(
        "--independent-markers",
        action="store_true",
        help="draw the survey's marker errors independently per stop (the old way)",
    )
    ap.add_argument(
        "--min-views",
        type=int,
        default=6,
        help="views per marker the survey's views are chosen for (0: all planned)",
    )
    args = ap.parse_args()
    cell = load_builtin_cell()
    stereo = cell_stereo(cell)
    cols = [
        "seed",
        "views",
        "survey_rms_um",
        "survey_max_um",
        "scale_ppm",
        "scale_sigma_ppm",
        "within_2s",
        "survey_s",
        "stops",
        "fallback",
        "hole_rms_um",
        "hole_max_um",
        "bestfit_rms_um",
        "bestfit_max_um",
        "within_U",
        "gauge_4to1",
        "n_position",
        "U_median_um",
        "resect_ms",
    ]
    if args.reference:
        cols += ["scipy_vs_gtsam_um", "scipy_s"]
    print("  ".join(f"{c:>12}" for c in cols))
    for seed in range(args.first_seed, args.first_seed + args.seeds):
        r = run_seed(seed, args, cell, stereo)
        print(
            "  ".join(
                f"{r.get(c, float('nan')):>12.4g}"
                if isinstance(r.get(c), float)
                else f"{r.get(c, '-')!s:>12}"
                for c in cols
            ),
            flush=True,
        )


if __name__ == "__main__":
    main()
