"""Benchmark of the tour planner: cycle time and planning time against reference methods.

Runs, in one process on the same cell, robot and limits: the built-in motorcycle
frame, generated instances of 25, 50, 100 and 250 holes (seeded random holes
on a frame-like set of tubes in front of the robot; the tubes are obstacles) and the
cluttered cells of ``benchmarks/cells/`` (``benchmarks/cluttered_cells.py``).
For each instance and method it reports the planning time (wall, by stage, and CPU:
this process's and the planner's helper process's, :mod:`planner.helper`) and the
cycle time (travel + 0.2 s dwell per stop). The machine's load average is printed
before and after: the machine may be shared, and the wall time drifts with the load.

- ours:   the default planner (LNS over IK candidates, OMPL where needed, ruckig).
- (a) naive: holes in file order, the IK candidate nearest the previous configuration,
          rest-to-rest motion (every OMPL waypoint a stop).
- (b) published: task-space TSP on the viewpoint positions (OR-Tools), then the best
          IK candidate per hole by a layered shortest path over every candidate, then
          paths and timing as ours.
- (c) ours with ten times the sequencing budget (effort and time cap), an estimate of the
          best tour.
- (o) ours with the OR-Tools GTSP sequencer (one disjunction per hole) at the default
          budget, to compare the two sequencers (instances up to 100 holes).

Usage: ``python benchmarks/plan_tour.py [--sizes 25 50 100 250] [--cells cluttered-20 ...]
[--seed 0] [--skip-c] [--no-builtin]``
"""

from __future__ import annotations

import argparse
import gc
import logging
import os
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import yaml
from ortools.constraint_solver import pywrapcp, routing_enums_pb2

from cell.config import CellConfig, builtin_cell_path, parse_cell
from cell.config.datums import without_drawing
from planner import Options, PlanningError, TourPlanner
from planner.costs import travel_time
from planner.sequence import SequenceResult, layered_best, tour_cost
from planner.timing import JointLimits
from planner.viewpoints import HoleCandidates
from robots.transforms import matrix_to_rpy

STAGES = ("viewpoints", "sequence", "paths", "timing")
#: the simpler methods the default planner must never lose to (issue 27)
BASELINES = ("(a) naive", "(b) published")
DWELL_S = 0.2  # the default dwell per stop, in every method
#: the cluttered cells (benchmarks/cluttered_cells.py)
CELLS = Path(__file__).parent / "cells"


# ---------------------------------------------------------------- instances
def _tube_pose(a: np.ndarray, b: np.ndarray) -> dict:
    z = (b - a) / np.linalg.norm(b - a)
    ref = np.array([1.0, 0, 0]) if abs(z[0]) < 0.9 else np.array([0, 1.0, 0])
    x = ref - z * (ref @ z)
    x /= np.linalg.norm(x)
    R = np.column_stack((x, np.cross(z, x), z))
    return {"xyz": [float(v) for v in (a + b) / 2], "rpy": [float(v) for v in matrix_to_rpy(R)]}


def generated_cell(n_holes: int, seed: int) -> CellConfig:
    """The built-in cell's robot, tool and table with ``n_holes`` holes on random tubes."""
    rng = np.random.default_rng(seed)
    data = yaml.safe_load(builtin_cell_path().read_text())
    tubes, obstacles = [], []
    for k in range(10):  # a frame-like tangle: tubes in the part's box, part frame coordinates
        a = rng.uniform([-0.35, -0.1, 0.0], [0.75, 0.1, 0.45])
        b = a + rng.uniform(0.35, 0.8) * _unit(rng.normal(size=3) * [1.0, 0.3, 0.6])
        b = np.clip(b, [-0.45, -0.12, -0.05], [0.85, 0.12, 0.5])
        if np.linalg.norm(b - a) < 0.2:
            b = a + np.array([0.3, 0.0, 0.1])
        r = float(rng.uniform(0.018, 0.03))
        tubes.append((a, b, r))
        cyl = {"radius": r, "length": float(np.linalg.norm(b - a))}
        obstacles.append({"name": f"tube{k}", "cylinder": cyl, "pose": _tube_pose(a, b)})
    holes = []
    while len(holes) < n_holes:
        a, b, r = tubes[int(rng.integers(len(tubes)))]
        axis = _unit(b - a)
        radial = _unit(np.cross(axis, rng.normal(size=3)))
        # facing the robot (part +y) or up (+z): the far side is a second set-up
        if radial @ _unit(np.array([0.0, 1.0, 0.6])) < 0.35:
            continue
        p = a + rng.uniform(0.1, 0.9) * (b - a) + r * radial
        holes.append(
            {
                "id": f"G{len(holes) + 1:03d}",
                "position": [round(float(v), 5) for v in p],
                "normal": [round(float(v), 6) for v in radial],
                "diameter": 0.008,
            }
        )
    data["name"] = f"generated-{n_holes}-seed{seed}"
    data["part"]["holes"] = holes
    without_drawing(data, 5e-5)  # the subset may leave datum features out
    data["part"]["obstacles"] = obstacles
    return parse_cell(yaml.safe_dump(data), f"<generated {n_holes} holes>")


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v)


# ---------------------------------------------------------------- reference sequencers
def naive_sequencer(
    home: np.ndarray, cands: list[HoleCandidates], limits: JointLimits
) -> SequenceResult:
    """Holes in file order; the candidate nearest (in travel time) the previous configuration."""
    t = time.perf_counter()
    lim = (limits.velocity, limits.acceleration, limits.jerk)
    q, choice = home, []
    for c in cands:
        k = int(np.argmin(travel_time(c.q, q, *lim)))
        choice.append(k)
        q = c.q[k]
    order = list(range(len(cands)))
    cost = tour_cost(
        home, np.array([cands[h].q[k] for h, k in zip(order, choice, strict=True)]), limits
    )
    return SequenceResult(order, choice, cost, time.perf_counter() - t, False)


def published_sequencer(home_tcp: np.ndarray, budget_s: float):
    """Task-space TSP on viewpoint positions, then a layered shortest path over every candidate."""

    def run(home: np.ndarray, cands: list[HoleCandidates], limits: JointLimits) -> SequenceResult:
        t = time.perf_counter()
        pts = np.vstack([home_tcp[None, :]] + [c.poses[0][:3, 3][None, :] for c in cands])
        dist = np.rint(np.linalg.norm(pts[:, None] - pts[None], axis=-1) * 1e6).astype(np.int64)
        manager = pywrapcp.RoutingIndexManager(len(pts), 1, 0)
        routing = pywrapcp.RoutingModel(manager)
        routing.SetArcCostEvaluatorOfAllVehicles(routing.RegisterTransitMatrix(dist.tolist()))
        params = pywrapcp.DefaultRoutingSearchParameters()
        params.first_solution_strategy = routing_enums_pb2.FirstSolutionStrategy.PATH_CHEAPEST_ARC
        params.local_search_metaheuristic = (
            routing_enums_pb2.LocalSearchMetaheuristic.GUIDED_LOCAL_SEARCH
        )
        params.time_limit.FromMilliseconds(int(budget_s * 1000))
        sol = routing.SolveWithParameters(params)
        order, idx = [], sol.Value(routing.NextVar(routing.Start(0)))
        while not routing.IsEnd(idx):
            order.append(manager.IndexToNode(idx) - 1)
            idx = sol.Value(routing.NextVar(idx))
        choice, cost = layered_best(home, [cands[h].q for h in order], limits)
        return SequenceResult(order, choice, cost, time.perf_counter() - t, False)

    return run


# ---------------------------------------------------------------- runs
@dataclass
class Row:
    instance: str
    method: str
    holes: int
    left_out: int
    cycle_s: float
    plan_s: float
    stages: dict[str, float]
    ompl: int
    cpu_s: float = float("nan")


def run_method(cell: CellConfig, method: str, seed: int) -> Row:
    default = Options(seed=seed)
    n = len(cell.part.holes)
    if method == "ours":
        planner = TourPlanner(default)
    elif method == "(a) naive":
        planner = TourPlanner(
            Options(seed=seed, pass_through_waypoints=False), None, naive_sequencer, "naive"
        )
    elif method == "(b) published":
        arm = cell.build_arm()
        home_tcp = arm.fk(cell.home_q(), "tcp")[:3, 3]
        seq = published_sequencer(home_tcp, default.budget_s(n))
        planner = TourPlanner(default, None, seq, "published")
    elif method == "(c) ours 10x":
        planner = TourPlanner(
            Options(seed=seed, effort=10.0, time_budget_s=10 * default.budget_s(n))
        )
    elif method == "(o) ours OR-Tools":
        planner = TourPlanner(Options(seed=seed, sequencer="ortools"))
    else:
        raise ValueError(method)
    cpu = time.process_time()
    tour = planner.plan(cell)
    cpu = time.process_time() - cpu + float(tour.settings.get("helper_cpu_time_s", 0.0))
    gc.collect()
    return Row(
        cell.name,
        method,
        len(tour.stops),
        len(tour.left_out),
        tour.cycle_time_s,
        tour.planning_time_s,
        dict(tour.timings_s),
        int(tour.settings.get("ompl_segments", 0)),
        cpu,
    )


def print_table(rows: list[Row]) -> None:
    head = (
        f"| {'instance':<22} | {'method':<18} | holes | left out | cycle s | vs ours | plan s "
        "| CPU s | viewp. | seq. | paths | timing | OMPL segs |"
    )
    print(head)
    print("|" + "|".join("-" * (len(c)) for c in head.split("|")[1:-1]) + "|")
    ours = {r.instance: r.cycle_s for r in rows if r.method == "ours"}
    for r in rows:
        rel = (r.cycle_s / ours[r.instance] - 1) * 100 if r.instance in ours else float("nan")
        st = r.stages
        print(
            f"| {r.instance:<22} | {r.method:<18} | {r.holes:5d} | {r.left_out:8d} "
            f"| {r.cycle_s:7.2f} "
            f"| {rel:+6.1f}% | {r.plan_s:6.2f} | {r.cpu_s:5.2f} | {st['viewpoints']:6.2f} "
            f"| {st['sequence']:4.2f} "
            f"| {st['paths']:5.2f} | {st['timing']:6.2f} | {r.ompl:9d} |"
        )


def _travel(r: Row) -> float:
    return r.cycle_s - r.holes * DWELL_S


def print_targets(rows: list[Row]) -> None:
    """Targets: cycle time (with dwell) and travel time (cycle minus dwell) vs (a), (b), (c)."""
    print(
        "\n| instance | ours vs (a): cycle / travel | ours vs (b): cycle / travel "
        "| ours vs (c): cycle | planning s (wall / CPU) | targets met (on cycle time) |"
    )
    print("|---|---|---|---|---|---|")
    by = {(r.instance, r.method): r for r in rows}
    for inst in dict.fromkeys(r.instance for r in rows):
        ours = by.get((inst, "ours"))
        if ours is None:
            print(f"| {inst} | | | | | no: ours failed |")
            continue
        a, b, c = (by.get((inst, m)) for m in ("(a) naive", "(b) published", "(c) ours 10x"))
        nan = float("nan")
        ra = (1 - ours.cycle_s / a.cycle_s) * 100 if a else nan
        ta = (1 - _travel(ours) / _travel(a)) * 100 if a else nan
        rb = (1 - ours.cycle_s / b.cycle_s) * 100 if b else nan
        tb = (1 - _travel(ours) / _travel(b)) * 100 if b else nan
        rc = (ours.cycle_s / c.cycle_s - 1) * 100 if c else nan
        limit = 3.0 if inst == "motorcycle-frame" else 5.0  # 250 holes in 5 s: issue 27
        timed = inst == "motorcycle-frame" or ours.holes >= 200
        ok = [ra >= 40 if a else None, rb >= 10 if b else None, rc <= 2 if c else None]
        ok.append(ours.plan_s <= limit if timed else None)
        # issue 27: ours no worse than any baseline (a, b) on any instance
        base = [r.cycle_s for m, r in ((m, by.get((inst, m))) for m in BASELINES) if r]
        ok.append(ours.cycle_s <= min(base) + 1e-9 if base else None)
        names = ("a", "b", "c", "time", "<= baselines")
        missed = [n for n, x in zip(names, ok, strict=True) if x is False]
        met = "yes" if not missed else "no: " + ", ".join(missed)
        print(
            f"| {inst} | {ra:.1f} % / {ta:.1f} % faster | {rb:.1f} % / {tb:.1f} % faster "
            f"| {rc:+.2f} % | {ours.plan_s:.2f} / {ours.cpu_s:.2f} | {met} |"
        )


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", type=int, nargs="*", default=[25, 50, 100, 250])
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--skip-c", action="store_true", help="skip the 10x-budget runs")
    ap.add_argument("--no-builtin", action="store_true")
    known = sorted(p.stem for p in CELLS.glob("*.yaml"))
    ap.add_argument(
        "--cells",
        nargs="*",
        default=known,
        help="cells of benchmarks/cells/ by name (default: every one; none: give no name)",
    )
    args = ap.parse_args(argv)
    for name in args.cells:
        if name not in known:
            ap.error(f"--cells {name}: not in {CELLS}; known: {' '.join(known)}")
    logging.basicConfig(level=logging.ERROR)
    print(f"load average before: {_load()}", file=sys.stderr)
    cells = [] if args.no_builtin else [parse_cell(builtin_cell_path().read_text(), "builtin")]
    cells += [generated_cell(n, seed=100 + n) for n in args.sizes]
    for name in args.cells:
        path = CELLS / f"{name}.yaml"
        cells.append(parse_cell(path.read_text(), str(path)))
    methods = ["ours", "(a) naive", "(b) published", "(c) ours 10x", "(o) ours OR-Tools"]
    rows, failed = [], []
    for cell in cells:
        for m in methods:
            if (m == "(c) ours 10x" and args.skip_c) or (
                m == "(o) ours OR-Tools" and len(cell.part.holes) > 100
            ):
                continue
            try:
                rows.append(run_method(cell, m, args.seed))
            except PlanningError as exc:  # e.g. a wall-time cap that bound under load
                print(f"  {cell.name} {m}: failed: {exc}", file=sys.stderr)
                failed.append(f"{cell.name} {m}: {exc}")
                continue
            r = rows[-1]
            print(
                f"  {r.instance} {r.method}: cycle {r.cycle_s:.2f} s, plan {r.plan_s:.2f} s",
                file=sys.stderr,
            )
    print_table(rows)
    print_targets(rows)
    for line in failed:
        print(f"\nfailed: {line}")
    cores = len(os.sched_getaffinity(0))
    print(f"\nload average (1, 5, 15 min) after: {_load()}; {cores} cores")
    return 0


def _load() -> str:
    return ", ".join(f"{x:.2f}" for x in os.getloadavg())


if __name__ == "__main__":
    sys.exit(main())
