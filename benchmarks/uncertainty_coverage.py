"""Does the stated uncertainty cover the truth? The whole demo job over many seeded runs.

    .venv/bin/python benchmarks/uncertainty_coverage.py [--seeds N] [--quick]

Each seed is a complete `holecell demo` (plan, warm-up with reference rounds, thermal
identification, all 41 holes) on the realistic simulated cell: the arm scatters by its
data-sheet repeatability, the true stereo head is off its calibration by a draw from the
calibration's uncertainty, the part is at 23 degC with a true expansion coefficient off the
material's figure, the thermometer reads it with noise. The simulator knows the true holes (their
20 degC geometry); a characteristic is covered when ``|measured - true| <= U`` (k = 2): the
position deviation (in the plane of the hole axis) and the diameter of every hole. The GD&T
characteristics of report.json (issue 19: position in the datum frame with its Monte Carlo U,
size) are checked against the true part's the same way (last column and line).

Target (issue 13): coverage between 90 and 99 %. A second table checks the stereo-calibration
component against a second method: Monte Carlo over whole calibrations re-triangulating the
stored edge points and refitting with the measurement's own circle fit.
"""

from __future__ import annotations

import argparse
import logging
import tempfile
import time
from pathlib import Path

import numpy as np

from cell.demo.demo import DemoOptions, run_demo


def demo_options(seed: int) -> DemoOptions:
    """The demo world of this benchmark: the realistic cell without geometric errors (the demo
    before issue 18; the fixture-frame coverage is what it checks), no cell calibration. The
    calibrated demo on drawn truths is ``benchmarks/demo_calibrated.py``."""
    return DemoOptions(seed=seed, geometry_errors=False, calibrate=False)


def coverage_runs(seeds: list[int]) -> list[dict]:
    """One demo per seed; per seed the coverage figures and the results."""
    out = []
    for seed in seeds:
        with tempfile.TemporaryDirectory() as tmp:
            t0 = time.process_time()
            res = run_demo(Path(tmp) / "run", demo_options(seed))
            gdt = gdt_coverage(Path(tmp) / "run", seed)
            tr = res.truth
            s = res.summary
            out.append({
                "seed": seed, "cov": tr.coverage, "n": tr.n_characteristics,
                "covered": tr.n_covered, "rms_um": tr.rms_m * 1e6,
                "dia_rms_um": tr.diameter_rms_m * 1e6,
                "conf": s["holes_conforming"], "inc": s["holes_inconclusive"],
                "nonconf": s["holes_nonconforming"], "cpu_s": time.process_time() - t0,
                "pos": tr.position_covered, "dia": tr.diameter_covered,
                "gdt_pos": gdt.of_kind("position"), "gdt_dia": gdt.of_kind("diameter"),
            })  # fmt: skip
            r = out[-1]
            print(
                f"| {seed} | {r['covered']}/{r['n']} | {100 * r['cov']:.1f} % | "
                f"{100 * np.mean(r['pos']):.1f} % | {100 * np.mean(r['dia']):.1f} % | "
                f"{r['conf']} / {r['inc']} / {r['nonconf']} | {r['cpu_s']:.0f} | "
                f"{100 * np.mean(r['gdt_pos']):.1f} % / {100 * np.mean(r['gdt_dia']):.1f} % |",
                flush=True,
            )
    return out


def gdt_coverage(run_dir: Path, seed: int):
    """The GD&T characteristics of a demo run (report.json) against the simulated part's true
    ones (:mod:`cell.gdt.truth_check`): position by its Monte Carlo U, size by the budget's."""
    import json

    from cell.config import load_builtin_cell
    from cell.demo.demo import demo_world
    from cell.gdt.truth_check import coverage, true_evaluation
    from cell.sim.world import SimWorld
    from robots.transforms import invert

    cell = load_builtin_cell()
    world = SimWorld(cell, demo_world(cell, demo_options(seed)))
    T = invert(cell.T_cell_part())
    centres = {k: T[:3, :3] @ h.position_m + T[:3, 3] for k, h in world.holes.items()}
    truth = true_evaluation(cell, centres, {k: h.diameter_m for k, h in world.holes.items()})
    doc = json.loads((run_dir / "report.json").read_text())
    return coverage(doc["characteristics"], truth)


def calibration_check(n_holes: int = 6, n_mc: int = 300) -> None:
    """Jacobian vs Monte Carlo of the stereo-calibration component on rendered holes."""
    from cell.uncertainty.calibration import (
        default_uncertainty,
        jacobian_covariance,
        monte_carlo_covariance,
    )
    from measure import measure_hole
    from measure.synth import render_hole_pair, standard_stereo

    st = standard_stereo()
    unc = default_uncertainty(st)
    rng = np.random.default_rng(5)
    print(
        "\n| hole | u centre x / y / z, Jacobian (um) | Monte Carlo (um) | u radius J / MC (um) |"
    )
    print("|---|---|---|---|")
    for i in range(n_holes):
        d = float(rng.choice([0.006, 0.010, 0.0194]))
        tilt = np.radians(rng.uniform(0, 30))
        n = np.array([np.sin(tilt), 0.0, -np.cos(tilt)])
        c = np.array([0.05 + rng.normal(0, 0.005), rng.normal(0, 0.005), 0.245])
        pair = render_hole_pair(st, c, n, d, seed=i)
        m = measure_hole(pair.left, pair.right, st, expected_diameter_m=d)
        pts = m.points_m[m.inliers]
        J = np.sqrt(np.diag(jacobian_covariance(st, pts, unc))) * 1e6
        M = np.sqrt(np.diag(monte_carlo_covariance(st, pts, unc, n_mc, seed=i))) * 1e6
        print(
            f"| {d * 1e3:.1f} mm, {np.degrees(tilt):.0f} deg | {J[0]:.2f} / {J[1]:.2f} / "
            f"{J[2]:.2f} | {M[0]:.2f} / {M[1]:.2f} / {M[2]:.2f} | {J[3]:.3f} / {M[3]:.3f} |"
        )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=12)
    ap.add_argument("--quick", action="store_true", help="two seeds")
    args = ap.parse_args()
    logging.getLogger("planner").setLevel(logging.ERROR)
    seeds = list(range(2 if args.quick else args.seeds))
    print(
        "| seed | covered | coverage | positions | diameters | proven / inconclusive / "
        "nonconforming | CPU s | GD&T position (MC) / size |"
    )
    print("|---|---|---|---|---|---|---|---|")
    runs = coverage_runs(seeds)
    n = sum(r["n"] for r in runs)
    k = sum(r["covered"] for r in runs)
    pos = np.concatenate([r["pos"] for r in runs])
    dia = np.concatenate([r["dia"] for r in runs])
    print(
        f"| all {len(runs)} | {k}/{n} | {100 * k / n:.1f} % | {100 * pos.mean():.1f} % | "
        f"{100 * dia.mean():.1f} % | | |"
    )
    ok = 0.90 <= k / n <= 0.99
    print(f"\ncoverage {100 * k / n:.1f} % (target 90-99 %): {'met' if ok else 'MISSED'}")
    gp = np.concatenate([r["gdt_pos"] for r in runs])
    gd = np.concatenate([r["gdt_dia"] for r in runs])
    g = np.concatenate([gp, gd])
    ok = 0.90 <= g.mean() <= 0.99
    print(f"GD&T characteristics in the datum frame: {100 * g.mean():.1f} % of {len(g)} "
          f"(positions by Monte Carlo {100 * gp.mean():.1f} %, sizes {100 * gd.mean():.1f} %; "
          f"target 90-99 %): {'met' if ok else 'MISSED'}")  # fmt: skip
    calibration_check()


if __name__ == "__main__":
    main()
