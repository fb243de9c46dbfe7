"""The whole demo (calibration, then the frame) on seeded realistic truths, against the targets.

    .venv/bin/python benchmarks/demo_calibrated.py [--seeds 10] [--variant NAME ...]
        [--method images|projected]

Each row is one complete ``holecell demo`` (``cell.demo.demo.run_demo``) on the truth
``CellTruth.drawn(seed)``: the cell calibrated first (the calibration's figures: hand-eye error
against the truth, wall time), then the 41 holes measured with it. Columns: hole position
error against the truth in the hole plane, in the datum frame A|B|C (the drawing's: what the
report's characteristics use), after a best fit of all holes (the measurement's own error,
without the datum features' levers), and in the fixture frame (with the base's and the part's
placement, which no arm calibration sees); the truth within U for positions and diameters
(datum frame: position by its Monte Carlo U, size by the budget's). Targets (issue 18): max
<= 50 um and RMS <= 25 um in the hole plane, 90-99 % within U.

Variants remove one error source from the truth, to see what limits the figures:
``no-calibration`` (the run uses the nominal kinematics), ``no-repeatability`` (RP 0),
``exact-head`` (the true stereo head is its calibration file), ``no-geometry`` (the truth
without D-H, head, base, part and plate errors: the demo before issue 18, calibrated anyway).
"""

from __future__ import annotations

import argparse
import logging
import tempfile
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from cell.config import load_builtin_cell
from cell.demo.demo import DemoOptions, run_demo
from cell.sim.truth import CellTruth

VARIANTS = ("default", "no-calibration", "no-repeatability", "exact-head", "no-geometry")


def options(seed: int, variant: str, method: str = "images") -> DemoOptions:
    """The demo's options of one seed and variant; ``method``: the calibration's
    (``"images"``: the demo's, plate rendered and detected; ``"projected"``: corners projected)."""
    cell = load_builtin_cell()
    truth = CellTruth.drawn(seed, cell)
    opts = DemoOptions(seed=seed, truth=truth, calibration_method=method)
    if variant == "no-calibration":
        return replace(opts, calibrate=False)
    if variant == "no-repeatability":
        return replace(opts, truth=replace(truth, repeatability_rp_m=0.0))
    if variant == "exact-head":
        return replace(opts, truth=replace(truth, calibration_sigma_scale=0.0))
    if variant == "no-geometry":
        z = CellTruth.zero(seed)
        flat = replace(truth, dh_errors=z.dh_errors, base_error=z.base_error,
                       tcp_error=z.tcp_error, part_placement_error=z.part_placement_error,
                       target_placement_error=z.target_placement_error)  # fmt: skip
        return replace(opts, truth=flat)
    return opts


def one(seed: int, variant: str, method: str = "images") -> dict:
    """Run one demo; its figures (um, %, s)."""
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        res = run_demo(Path(tmp) / "run", options(seed, variant, method))
        wall = time.perf_counter() - t0
    d, tr, c = res.datum, res.truth, res.calibration
    return {
        "seed": seed, "variant": variant,
        "he_mm": c.hand_eye_error_m * 1e3 if c else float("nan"),
        "he_deg": np.degrees(c.hand_eye_error_rad) if c else float("nan"),
        "cal_s": c.seconds if c else 0.0,
        "drf_rms": d.rms_in_plane_m * 1e6, "drf_max": d.max_in_plane_m * 1e6,
        "bf_rms": d.best_fit_rms_in_plane_m * 1e6, "bf_max": d.best_fit_max_in_plane_m * 1e6,
        "fix_rms": tr.rms_in_plane_m * 1e6,
        "pos": d.position_covered, "dia": d.diameter_covered, "wall_s": wall,
    }  # fmt: skip


def row(r: dict) -> str:
    pos = 100 * np.mean(r["pos"]) if r["pos"] else float("nan")
    dia = 100 * np.mean(r["dia"]) if r["dia"] else float("nan")
    return (f"| {r['seed']} | {r['variant']} | {r['he_mm']:.4f} mm, {r['he_deg']:.4f}° | "
            f"{r['cal_s']:.1f} | {r['drf_rms']:.1f} / {r['drf_max']:.1f} | "
            f"{r['bf_rms']:.1f} / {r['bf_max']:.1f} | {r['fix_rms']:.0f} | {pos:.1f} % | "
            f"{dia:.1f} % | {r['wall_s']:.0f} |")  # fmt: skip


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=10)
    ap.add_argument("--first", type=int, default=0, help="first seed")
    ap.add_argument("--variant", action="append", choices=VARIANTS, default=None)
    ap.add_argument("--method", choices=("images", "projected"), default="images",
                    help="the calibration's observations: images (the demo's) or projected "
                    "corners (seconds a seed)")  # fmt: skip
    args = ap.parse_args()
    logging.getLogger("planner").setLevel(logging.ERROR)
    print("| seed | variant | hand-eye error | calibration s | datum frame RMS / max (um) | "
          "best fit RMS / max (um) | fixture frame RMS (um) | positions within U | "
          "diameters within U | wall s |")  # fmt: skip
    print("|---|---|---|---|---|---|---|---|---|---|")
    rows = []
    for variant in args.variant or ["default"]:
        for seed in range(args.first, args.first + args.seeds):
            rows.append(one(seed, variant, args.method))
            print(row(rows[-1]), flush=True)
    for variant in args.variant or ["default"]:
        rs = [r for r in rows if r["variant"] == variant]
        pos = np.concatenate([r["pos"] for r in rs])
        dia = np.concatenate([r["dia"] for r in rs])
        print(f"| all {len(rs)} | {variant} | | | {np.mean([r['drf_rms'] for r in rs]):.1f} / "
              f"{max(r['drf_max'] for r in rs):.1f} | {np.mean([r['bf_rms'] for r in rs]):.1f} / "
              f"{max(r['bf_max'] for r in rs):.1f} | | {100 * pos.mean():.1f} % | "
              f"{100 * dia.mean():.1f} % | |")  # fmt: skip


if __name__ == "__main__":
    main()
