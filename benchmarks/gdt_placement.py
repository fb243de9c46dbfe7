"""The part off its fixture: do the datum-frame results stay, and is the placement found?

    .venv/bin/python benchmarks/gdt_placement.py [--seeds 0 1] [--mm 1.5] [--deg 0.4]

Per seed two whole demos of the built-in frame (realistic cell: repeatability, the head off
its calibration) with the same seed: one with the part where the fixture means to hold it,
one with the part placed off it by ``--mm`` and ``--deg`` (the simulated truth file's
``part_placement_error``). Reported:

- every position and size characteristic of the second run against the first: the change
  ``|value_2 - value_1|`` within ``sqrt(U_1^2 + U_2^2)`` (two independent runs);
- the reported placement against the true one, per axis within its U (k = 2): the true
  DRF's placement (the evaluation of the true holes), which differs from the truth file's
  ``part_placement_error`` by the datum features' own machining scatter (printed too);
- the coverage of the characteristics against the true part (truth within U), both runs.

Issue 19's done-when: deviations in the datum frame unchanged within U; placement = truth
within U; coverage 90-99 %.
"""

from __future__ import annotations

import argparse
import json
import tempfile
from dataclasses import replace
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from cell.config import load_builtin_cell
from cell.demo.demo import DemoOptions, demo_truth, demo_world, run_demo
from cell.gdt.truth_check import coverage, placement_error, true_evaluation
from cell.sim.world import SimWorld
from robots.transforms import invert


def placement_of(mm: float, deg: float) -> np.ndarray:
    """A placement of ``mm`` and ``deg`` in a fixed oblique direction (4x4)."""
    T = np.eye(4)
    axis = np.array([0.3, 0.5, 0.81])
    T[:3, :3] = Rotation.from_rotvec(np.radians(deg) * axis / np.linalg.norm(axis)).as_matrix()
    T[:3, 3] = mm * 1e-3 * np.array([0.8, -0.36, 0.48])
    return T


def one_run(out: Path, seed: int, T_err: np.ndarray | None) -> tuple[dict, dict]:
    """A demo; its report.json and the true characteristics' coverage."""
    cell = load_builtin_cell()
    opts = DemoOptions(seed=seed, geometry_errors=False, calibrate=False)  # the placement alone
    truth = demo_truth(cell, opts)
    if T_err is not None:
        truth = replace(truth, part_placement_error=T_err)
    opts = replace(opts, truth=truth)
    run_demo(out, opts)
    doc = json.loads((out / "report.json").read_text())
    world = SimWorld(cell, demo_world(cell, opts))
    T = invert(cell.T_cell_part())  # the nominal part frame: where the fixture means it
    centres = {k: T[:3, :3] @ h.position_m + T[:3, 3] for k, h in world.holes.items()}
    truth = true_evaluation(cell, centres, {k: h.diameter_m for k, h in world.holes.items()})
    cov = coverage(doc["characteristics"], truth)
    return doc, {
        "truth": truth,
        "fraction": cov.fraction,
        "position": float(np.mean(cov.of_kind("position"))),
        "diameter": float(np.mean(cov.of_kind("diameter"))),
        "n": len(cov.rows),
    }


def compare(doc0: dict, doc1: dict, truth1, T_err: np.ndarray) -> dict:
    """Characteristics of the placed run against the unplaced one; placement against the
    true DRF's (and, for the record, the truth file's placement against the true DRF's)."""
    c0 = {c["id"]: c for c in doc0["characteristics"]}
    same = []
    for c in doc1["characteristics"]:
        a = c0.get(c["id"])
        if a is None or a["value_m"] is None or c["value_m"] is None:
            continue
        same.append(abs(c["value_m"] - a["value_m"]) <= np.hypot(c["U_m"], a["U_m"]))
    p = doc1["placement"]
    err = placement_error(p, truth1)
    true_T = truth1.placement["T_fixture_part"]
    scatter = Rotation.from_quat(true_T["quat_xyzw"]).as_rotvec() - Rotation.from_matrix(
        T_err[:3, :3]).as_rotvec()  # fmt: skip
    return {
        "unchanged": float(np.mean(same)), "n": len(same),
        "placement_xyz_err_um": (np.array(err["xyz_m"]) * 1e6).round(1).tolist(),
        "U_xyz_um": (np.array(p["U_xyz_m"]) * 1e6).round(1).tolist(),
        "placement_rot_err_urad": (np.array(err["rotation_rad"]) * 1e6).round(0).tolist(),
        "U_rot_urad": (np.array(p["U_rotation_rad"]) * 1e6).round(0).tolist(),
        "placement_within_U": err["within_U"],
        "datum_scatter_um_urad": (
            ((np.array(true_T["xyz"]) - T_err[:3, 3]) * 1e6).round(1).tolist(),
            (scatter * 1e6).round(0).tolist()),
    }  # fmt: skip


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, nargs="+", default=[0])
    ap.add_argument("--mm", type=float, default=1.5)
    ap.add_argument("--deg", type=float, default=0.4)
    args = ap.parse_args()
    T_err = placement_of(args.mm, args.deg)
    print("| seed | unchanged within U | placement err xyz (um) / U | rot err (urad) / U | "
          "coverage on / off fixture (pos, dia) |")  # fmt: skip
    print("|---|---|---|---|---|")
    for seed in args.seeds:
        with tempfile.TemporaryDirectory() as tmp:
            doc0, cov0 = one_run(Path(tmp) / "on", seed, None)
            doc1, cov1 = one_run(Path(tmp) / "off", seed, T_err)
        r = compare(doc0, doc1, cov1["truth"], T_err)
        print(
            f"| {seed} | {r['unchanged'] * 100:.1f} % of {r['n']} | "
            f"{r['placement_xyz_err_um']} / {r['U_xyz_um']} | "
            f"{r['placement_rot_err_urad']} / {r['U_rot_urad']} "
            f"({'within' if r['placement_within_U'] else 'NOT within'} U) | "
            f"{cov0['fraction'] * 100:.1f} % ({cov0['position'] * 100:.0f}, "
            f"{cov0['diameter'] * 100:.0f}) / {cov1['fraction'] * 100:.1f} % "
            f"({cov1['position'] * 100:.0f}, {cov1['diameter'] * 100:.0f}) |",
            flush=True,
        )
        print(
            f"  true DRF vs the truth file's placement (datum features' scatter): "
            f"{r['datum_scatter_um_urad']} (um, urad)",
            flush=True,
        )


if __name__ == "__main__":
    main()
