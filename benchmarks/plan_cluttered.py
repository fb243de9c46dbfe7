"""Benchmark of tour quality and stability on cluttered cells, against the best-known tours.

Instances: the built-in motorcycle frame and the generated cluttered cells
``benchmarks/cells/cluttered-{20,40,80}.yaml`` (see ``benchmarks/cluttered_cells.py``).
Per instance:

- default: ``holecell plan`` as shipped (multi-start, ``DEFAULT_STARTS`` starts on the
  local cores) for base seeds 0..7: median, worst, best and spread of the cycle time;
- each sequencer alone (one start; ``lns``, ``pyvrp``, ``ortools``) for seeds 0..7
  (fewer with ``--quick``);
- long runs: every sequencer at 20× the effort and time cap, two seeds (OR-Tools one);
- naive: holes in file order, nearest IK candidate, rest-to-rest (benchmarks/plan_tour.py).

The best-known tour is the shortest cycle time of all of these runs (the default, the
three sequencers, the long runs — PyVRP's hybrid search is the independent reference).
Planning time: wall time of a whole multi-start plan, and the CPU time per start (every
thread of the start's process), because the machine is shared and the wall time drifts
with the load, which is printed.

Usage: ``python benchmarks/plan_cluttered.py [--instances frame 20 40 80] [--quick]
[--json out.json]``; ``--timing-only 250`` plans the 250-hole cell once with the default.
"""

from __future__ import annotations

import argparse
import json
import logging
import os
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))

from cell.config import builtin_cell_path, load_cell
from plan_tour import naive_sequencer
from planner import Options, PlanningError, Tour, TourPlanner
from planner.engines import LocalEngine
from planner.multistart import DEFAULT_STARTS, plan_multistart, plan_one
from planner.sequence import SEQUENCERS

CELLS = Path(__file__).parent / "cells"


def _cell(name: str):
    if name == "frame":
        return load_cell(builtin_cell_path())
    return load_cell(CELLS / f"cluttered-{name}.yaml")


def _single(engine: LocalEngine, cell, options: list[Options]) -> list[Tour | str]:
    return engine.map(plan_one, [(cell, o) for o in options])


def _stats(values: list[float]) -> dict[str, float]:
    return {
        "median": statistics.median(values),
        "worst": max(values),
        "best": min(values),
        "spread_pct": (max(values) / min(values) - 1) * 100,
    }


def run_instance(
    name: str,
    engine: LocalEngine,
    seeds: int,
    quick: bool,
    minimal: bool = False,
    long_runs: bool = True,
) -> dict:
    """Every run of one instance (see module docstring); cycle times in s.

    ``minimal``: the default's starts stand for the LNS single starts (they are exactly
    those: seeds 0 .. 2·seeds−1), PyVRP two seeds, OR-Tools one, long runs LNS and PyVRP.
    """
    cell = _cell(name)
    out: dict = {"instance": cell.name, "runs": {}}
    default = []
    for b in range(seeds):
        t = time.perf_counter()
        tour = plan_multistart(cell, Options(seed=b), DEFAULT_STARTS, engine)
        default.append(
            {
                "seed": b,
                "cycle_s": tour.cycle_time_s,
                "wall_s": time.perf_counter() - t,
                "cpu_per_start_s": tour.settings["cpu_time_s"],
                "cpu_shared_s": tour.settings.get("shared_cpu_time_s", 0.0),
                "holes": len(tour.stops),
                "ompl": tour.settings["ompl_segments"],
                "start_cycles_s": tour.settings["start_cycle_times_s"],
                "start_cpu_s": tour.settings["start_cpu_times_s"],
            }
        )
        print(f"  {cell.name} default seed {b}: {tour.cycle_time_s:.2f} s", file=sys.stderr)
    out["runs"]["default"] = default
    n_seeds = 4 if quick else seeds
    if minimal:
        starts = [
            (r["seed"] * DEFAULT_STARTS + k, c)
            for r in default
            for k, c in enumerate(r["start_cycles_s"])
        ]
        out["runs"]["lns"] = [{"seed": s, "cycle_s": c} for s, c in starts]
    for seq in SEQUENCERS:
        if minimal and seq == "lns":
            continue
        n_seq = (2 if seq == "pyvrp" else 1) if minimal else n_seeds
        res = _single(engine, cell, [Options(seed=s, sequencer=seq) for s in range(n_seq)])
        out["runs"][seq] = [_row(s, r) for s, r in enumerate(res)]
        print(f"  {cell.name} {seq}: {[r['cycle_s'] for r in out['runs'][seq]]}", file=sys.stderr)
    n = len(cell.part.holes)
    for seq in SEQUENCERS if long_runs else ():
        if minimal and seq == "ortools":
            continue
        long_seeds = [0] if seq == "ortools" or quick or minimal else [0, 1]
        opts = [
            Options(
                seed=1000 + s, sequencer=seq, effort=20.0, time_budget_s=20 * Options().budget_s(n)
            )
            for s in long_seeds
        ]
        res = _single(engine, cell, opts)
        out["runs"][f"{seq} 20x"] = [
            _row(1000 + s, r) for s, r in zip(long_seeds, res, strict=True)
        ]
        print(
            f"  {cell.name} {seq} 20x: {[r['cycle_s'] for r in out['runs'][f'{seq} 20x']]}",
            file=sys.stderr,
        )
    try:
        naive = TourPlanner(
            Options(pass_through_waypoints=False), None, naive_sequencer, "naive"
        ).plan(cell)
        out["runs"]["naive"] = [{"seed": 0, "cycle_s": naive.cycle_time_s}]
    except PlanningError as exc:  # file order through the clutter: OMPL may give up
        out["runs"]["naive"] = [{"seed": 0, "cycle_s": None, "error": str(exc)}]
    everything = [r["cycle_s"] for k, rows in out["runs"].items() if k != "naive" for r in rows]
    out["best_known_s"] = min(c for c in everything if c is not None)
    return out


def _row(seed: int, r: Tour | str) -> dict:
    if isinstance(r, str):
        return {"seed": seed, "cycle_s": None, "error": r}
    return {
        "seed": seed,
        "cycle_s": r.cycle_time_s,
        "cpu_s": r.settings["cpu_time_s"],
        "ompl": r.settings["ompl_segments"],
        "hit_time_limit": r.settings["sequence_hit_time_limit"],
    }


def print_tables(results: list[dict]) -> None:
    print(
        "| instance | method | runs | median s | worst s | best s | spread | median vs best-known "
        "| worst vs best-known | median vs naive | CPU s per start (median) "
        "| CPU s shared + slowest start (median, worst) | wall s (median) |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for res in results:
        best = res["best_known_s"]
        naive = res["runs"]["naive"][0]["cycle_s"] or float("nan")
        for method, rows in res["runs"].items():
            cyc = [r["cycle_s"] for r in rows if r["cycle_s"] is not None]
            if not cyc:
                print(f"| {res['instance']} | {method} | 0 | failed: {rows[0].get('error')} |")
                continue
            st = _stats(cyc)
            cpu = [r.get("cpu_per_start_s", r.get("cpu_s")) for r in rows if r["cycle_s"]]
            cpu = [c for c in cpu if c is not None]
            wall = [r["wall_s"] for r in rows if "wall_s" in r]
            # a default run: the shared part (once) plus its slowest start, what 2 cores take
            total = [r["cpu_shared_s"] + max(r["start_cpu_s"]) for r in rows if "start_cpu_s" in r]
            total_s = f"{statistics.median(total):.2f}, {max(total):.2f}" if total else "nan"
            print(
                f"| {res['instance']} | {method} | {len(cyc)} | {st['median']:.2f} "
                f"| {st['worst']:.2f} | {st['best']:.2f} | {st['spread_pct']:.1f} % "
                f"| {(st['median'] / best - 1) * 100:+.2f} % "
                f"| {(st['worst'] / best - 1) * 100:+.2f} % | {st['median'] / naive:.2f} "
                f"| {statistics.median(cpu) if cpu else float('nan'):.2f} | {total_s} "
                f"| {statistics.median(wall) if wall else float('nan'):.2f} |"
            )
        print(f"| {res['instance']} | best-known | | {best:.2f} | | | | | | | | | |")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--instances", nargs="*", default=["frame", "20", "40", "80"])
    ap.add_argument("--seeds", type=int, default=8)
    ap.add_argument("--quick", action="store_true", help="4 seeds per sequencer, one long run")
    ap.add_argument("--minimal", action="store_true", help="see run_instance")
    ap.add_argument("--no-long", action="store_true", help="skip the 20x runs")
    ap.add_argument("--jobs", type=int, default=None)
    ap.add_argument("--json", type=Path, default=None)
    ap.add_argument("--timing-only", nargs="*", default=None, help="plan these once, time it")
    ap.add_argument("--tables-of", nargs="*", type=Path, default=None, help="print saved runs")
    args = ap.parse_args(argv)
    if args.tables_of:
        print_tables([res for p in args.tables_of for res in json.loads(p.read_text())])
        return 0
    logging.basicConfig(level=logging.ERROR)
    engine = LocalEngine(args.jobs)
    print(f"load average at start: {os.getloadavg()}", file=sys.stderr)
    if args.timing_only is not None:
        for name in args.timing_only:
            cell = _cell(name)
            t = time.perf_counter()
            tour = plan_multistart(cell, Options(), DEFAULT_STARTS, engine)
            print(
                f"{cell.name}: {len(tour.stops)} holes, cycle {tour.cycle_time_s:.2f} s, "
                f"wall {time.perf_counter() - t:.1f} s, "
                f"CPU shared {tour.settings.get('shared_cpu_time_s', 0.0):.1f} s + per start "
                f"{', '.join(f'{c:.1f}' for c in tour.settings['start_cpu_times_s'])} s, "
                f"load {os.getloadavg()[0]:.1f}"
            )
        return 0
    results = []
    for name in args.instances:
        results.append(
            run_instance(name, engine, args.seeds, args.quick, args.minimal, not args.no_long)
        )
        if args.json:
            args.json.write_text(json.dumps(results, indent=1))
        print(f"load average after {name}: {os.getloadavg()}", file=sys.stderr)
    print_tables(results)
    print(f"\nload average at the end: {os.getloadavg()}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
