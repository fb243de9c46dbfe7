"""Referenced against robot-only, on the same simulated truths, through the whole pipeline:
``holecell demo`` with and without referencing (docs/referencing.md).

For each seed the demo runs twice on the same truth (:meth:`cell.sim.truth.CellTruth.drawn`,
or the large-error truth with ``--large``): once referenced (the survey tour driven on the
simulated controller, the markers rendered, detected and identified in both cameras, one
bundle adjustment, then every stop resected against the network from its own hole pair) and
once robot-only (``--no-referencing``: the holes carried into the part by the calibrated arm
and the thermal model). Both use the same cell calibration method (``--calibration-method``,
default "projected": the plate's corners projected at the planned views, seconds instead of a
minute of rendering; "images" drives the calibration tour as the demo does).

Printed per seed and path: the survey against the true markers (RMS and worst after a rigid
fit, scale error, the share of marker coordinates within their stated 2 sigma, the centre noise
the covariances are stated at, ``sigma_eff_px``), the holes' position
error against the truth in the datum frame A|B|C in the hole plane (RMS, worst), the truth
within U and ``|reported - true| / U`` of the position characteristics (median and 95th
percentile: 1 for an honest U at k = 2), the position characteristics with U <= 1/4 of their
zone, the median U, the stops referenced, the survey's robot time (planned, and on the
simulator's clock, which also runs while each pair renders) and adjustment time, the
CPU time per stop of locating it (median; both passes of the bias and the resection,
:func:`cell.run.referenced.locate_stop`; ``replay_ms``: the same stops located again after the
run, without its workers rendering beside them), the demo's wall time, and the median standard
uncertainty of a referenced hole's position from the head's calibration, the survey's markers, the
resection, the circle fit and the part's temperature (``u_*_um``).
``--arm-x`` and ``--thermal-x`` multiply the arm's repeatability and the thermal drift;
``--sigma-floor-px`` sets the simulated head's centre-noise floor (default: the demo's,
:data:`cell.demo.survey.SIM_SIGMA_FLOOR_PX`; 0.02 is a real head's).

    python benchmarks/referenced_demo.py [--seeds 3] [--large] [--arm-x 1] [--thermal-x 1]
        [--sigma-floor-px F]
"""

from __future__ import annotations

import argparse
import json
import tempfile
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

import cell.run.runner as run_module
from cell.config import load_builtin_cell
from cell.demo import survey as demo_survey
from cell.demo.demo import DemoOptions, run_demo
from cell.gdt.truth_check import coverage, true_evaluation
from cell.run.referenced import locate_stop
from cell.sim.truth import CellTruth
from cell.sim.world import SimWorld, WorldOptions
from robots.transforms import invert, so3_exp, so3_log


def _large(t: CellTruth) -> CellTruth:
    def grow(T: np.ndarray) -> np.ndarray:
        out = np.eye(4)
        out[:3, :3] = so3_exp(3 * so3_log(T[:3, :3]))
        out[:3, 3] = 3 * T[:3, 3]
        return out

    return replace(t, dh_errors=3 * t.dh_errors, base_error=grow(t.base_error),
                   tcp_error=grow(t.tcp_error),
                   part_placement_error=grow(t.part_placement_error))  # fmt: skip


def _u_ratios(cell, truth: CellTruth, doc: dict) -> list[float]:
    """``|reported - true| / U`` of every position characteristic (1 at the edge of U; an
    honest U at k = 2 has 95 % of them below 1): the true part from the simulator's holes."""
    world = SimWorld(cell, WorldOptions(truth=truth))
    T = invert(cell.T_cell_part())
    centres = {k: T[:3, :3] @ h.position_m + T[:3, 3] for k, h in world.holes.items()}
    true = true_evaluation(cell, centres, {k: h.diameter_m for k, h in world.holes.items()})
    rows = coverage(doc.get("characteristics", []), true).rows
    kinds = {c["id"]: c["kind"] for c in doc.get("characteristics", [])}
    return [abs(v - t) / U for k, (v, U, t) in rows.items() if kinds.get(k) == "position" and U > 0]


def _figures(res, run_dir: Path, cell=None, truth: CellTruth | None = None) -> dict:
    doc = json.loads((run_dir / "report.json").read_text())
    pos = [c for c in doc.get("characteristics", [])
           if c["kind"] == "position" and c.get("U_m") is not None]  # fmt: skip
    refs = [h.extra.get("referencing") for h in res.run.stored]
    out = {
        "holes_rms_um": 1e6 * res.datum.rms_in_plane_m,
        "holes_max_um": 1e6 * res.datum.max_in_plane_m,
        "bestfit_rms_um": 1e6 * res.datum.best_fit_rms_in_plane_m,
        "within_U": float(np.mean(res.datum.position_covered))
        if res.datum.position_covered
        else float("nan"),
        "at_4to1": sum(c["U_m"] <= 0.25 * c["zone_diameter_m"] for c in pos),
        "n_pos": len(pos),
        "U_median_um": 1e6 * float(np.median([c["U_m"] for c in pos])) if pos else float("nan"),
        "referenced": sum(1 for x in refs if x and x.get("referenced")),
        "wall_s": res.timings["total_s"],
    }
    holes = [h for h in doc.get("holes", []) if h.get("referenced")]
    for key, col in U_PARTS.items():  # the budget's rows, median over the referenced holes
        vals = [h.get(f"u_{key}_position_m") for h in holes]
        vals = [v for v in vals if v is not None]
        out[col] = 1e6 * float(np.median(vals)) if vals else float("nan")
    if cell is not None and truth is not None:
        q = _u_ratios(cell, truth, doc)
        if q:
            out["ratio_med"], out["ratio_p95"] = float(np.median(q)), float(np.quantile(q, 0.95))
    locate = [t["locate_cpu_s"] for t in res.run.hole_timings if "locate_cpu_s" in t]
    out["locate_ms"] = 1e3 * float(np.median(locate)) if locate else float("nan")
    if res.survey is not None:
        s = res.survey
        out |= {"survey_rms_um": 1e6 * s.rms_m, "survey_max_um": 1e6 * s.worst_m,
                "scale_ppm": s.scale_error_ppm, "within_2s": s.within_2sigma,
                "sigma_eff_px": s.result.sigma_effective_px,
                "survey_plan_s": s.planned_robot_time_s, "survey_robot_s": s.robot_time_s,
                "survey_solve_s": s.solve_s,
                "survey_s": s.seconds, "views": s.result.n_views}  # fmt: skip
    return out


#: the budget rows printed (median standard uncertainty of a referenced hole's position, um)
U_PARTS = {
    "stereo_calibration": "u_head_um",
    "survey_markers": "u_net_um",
    "resection": "u_res_um",
    "circle_fit": "u_fit_um",
    "part_temperature": "u_temp_um",
}
COLS = ("seed", "path", "views", "survey_rms_um", "survey_max_um", "scale_ppm", "within_2s",
        "sigma_eff_px", "survey_plan_s", "survey_robot_s", "survey_solve_s", "referenced",
        "holes_rms_um", "holes_max_um", "bestfit_rms_um", "within_U", "ratio_med", "ratio_p95",
        "at_4to1", "n_pos", "U_median_um", "locate_ms", "replay_ms", "wall_s",
        *U_PARTS.values())  # fmt: skip


#: the arguments of every stop's :func:`locate_stop` in the run (replayed after it)
_LOCATED: list[tuple] = []


def _recording_locate(*args):
    _LOCATED.append(args)
    return locate_stop(*args)


def _replayed_ms() -> float:
    """Median CPU time (ms) of locating the run's stops again once it is over: the same stops
    without the run's workers rendering beside them."""
    times = []
    for args in _LOCATED:
        t0 = time.thread_time()
        locate_stop(*args)
        times.append(time.thread_time() - t0)
    _LOCATED.clear()
    return 1e3 * float(np.median(times)) if times else float("nan")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--first-seed", type=int, default=0)
    ap.add_argument("--large", action="store_true", help="three times the realistic errors")
    ap.add_argument("--arm-x", type=float, default=1.0, help="multiply the arm's repeatability")
    ap.add_argument("--thermal-x", type=float, default=1.0, help="multiply the thermal drift")
    ap.add_argument("--calibration-method", default="projected", choices=("projected", "images"))
    ap.add_argument("--only", choices=("referenced", "robot"), default=None)
    ap.add_argument(
        "--sigma-floor-px",
        type=float,
        default=None,
        help="the simulated head's centre-noise floor (px; default the demo's)",
    )
    args = ap.parse_args()
    if args.sigma_floor_px is not None:
        demo_survey.SIM_SIGMA_FLOOR_PX = args.sigma_floor_px
    cell = load_builtin_cell()
    run_module.locate_stop = _recording_locate  # the stops recorded for the replay
    print("  ".join(f"{c:>14}" for c in COLS), flush=True)
    for seed in range(args.first_seed, args.first_seed + args.seeds):
        t = CellTruth.drawn(seed, cell)
        t = _large(t) if args.large else t
        t = replace(t, repeatability_rp_m=args.arm_x * t.repeatability_rp_m)
        paths = [p for p in ("referenced", "robot") if args.only in (None, p)]
        for path in paths:
            with tempfile.TemporaryDirectory() as tmp:
                run_dir = Path(tmp) / "demo"
                opts = DemoOptions(seed=seed, truth=t, referencing=path == "referenced",
                                   calibration_method=args.calibration_method,
                                   thermal_scale=args.thermal_x)  # fmt: skip
                t0 = time.perf_counter()
                res = run_demo(run_dir, opts)
                r = {"seed": seed, "path": path, **_figures(res, run_dir, cell, t)}
                r["wall_s"] = time.perf_counter() - t0
                r["replay_ms"] = _replayed_ms()
            print("  ".join(f"{r.get(c, float('nan')):>14.4g}" if isinstance(r.get(c), float)
                            else f"{r.get(c, '-')!s:>14}" for c in COLS), flush=True)  # fmt: skip


if __name__ == "__main__":
    main()
