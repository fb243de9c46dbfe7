"""Where the demo's time goes, by stage: ``holecell demo`` run in this process, timed.

Runs :func:`cell.demo.demo.run_demo` (the built-in cell, the default options, no recording)
with timers around its stages and their main parts, and prints per stage the wall time and,
where the work runs in this process, its CPU time (all threads), then the demo's own figures
(the calibration tour's cache use, the calibration's move / capture / detect / solve walls,
the run's per-hole laps). Planning runs the reference and calibration tours in worker
processes: their time shows as the wait for them (``plan: wait for workers``).

Targets (issue 27): the demo in ≤ 60 s wall on the 2-core machine. On a shared machine
wall times include waiting for a CPU; the load average is printed.

Run: ``.venv/bin/python benchmarks/profile_demo.py`` (a full demo: about 2 min) or
``--quick`` (``--calibration-method projected``: no calibration tour driven).
"""

from __future__ import annotations

import argparse
import functools
import os
import sys
import tempfile
import threading
import time
from collections import defaultdict
from pathlib import Path

import cell.calibration.capture as capture
import cell.calibration.capture.tour as cal_tour
import cell.demo.demo as demo
import cell.run.inspect as inspect_hole
import cell.run.runner as runner
import cell.sim.camera as sim_camera
import planner.planner as tour_planner
from cell.demo.demo import DemoOptions, run_demo

TARGET_S = 60.0
#: (label, owner, attribute): the functions timed, in the order printed
TIMED = (
    ("plan: all tours", demo, "plan_demo"),
    ("plan: hole tour (this process)", tour_planner.TourPlanner, "plan"),
    ("calibration: all", demo, "_calibration"),
    ("calibration: tour driven and solved", capture, "run_calibration_tour"),
    ("calibration: solve", cal_tour, "solve_calibration"),
    ("camera: render a pair", sim_camera.SimCamera, "capture"),
    ("run: all", demo, "_run_sim"),
    ("run: measure a hole", runner, "measure_hole"),
    ("run: measure a hole (inspect)", inspect_hole, "measure_hole"),
    ("report: protocol", demo, "write_report"),
    ("report: errors vs truth", demo, "datum_truth_error"),
)

_lock = threading.Lock()
_wall: dict[str, float] = defaultdict(float)
_cpu: dict[str, float] = defaultdict(float)
_calls: dict[str, int] = defaultdict(int)
_runs: list[object] = []


def _timed(label: str, fn):
    @functools.wraps(fn)
    def wrapper(*args, **kwargs):
        t, c = time.perf_counter(), time.thread_time()
        try:
            out = fn(*args, **kwargs)
        finally:
            with _lock:
                _wall[label] += time.perf_counter() - t
                _cpu[label] += time.thread_time() - c
                _calls[label] += 1
        if label.startswith("calibration: tour"):
            _runs.append(out)
        return out

    return wrapper


def _install() -> None:
    for label, owner, name in TIMED:
        setattr(owner, name, _timed(label, getattr(owner, name)))


def main(argv: list[str] | None = None) -> int:
    """Run one demo and print the table; exit code 1 when its wall time misses the target."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="projected calibration (no tour driven)")
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args(argv)
    _install()
    method = "projected" if args.quick else "images"
    c0, t0 = time.process_time(), time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        res = run_demo(Path(tmp) / "run", DemoOptions(seed=args.seed, calibration_method=method))
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    print(f"holecell demo, seed {args.seed}, calibration {method}: by stage (s)")
    print(f"| {'stage':<38} | calls | wall s | cpu s (this process) |")
    print(f"|{'-' * 40}|-------|--------|----------------------|")
    for label, _, _ in TIMED:
        if _calls[label]:
            print(
                f"| {label:<38} | {_calls[label]:5d} | {_wall[label]:6.1f} | {_cpu[label]:20.1f} |"
            )
    waited = _wall["plan: all tours"] - _wall["plan: hole tour (this process)"]
    print(f"| {'plan: wait for workers':<38} |       | {waited:6.1f} |                      |")
    print(f"| {'total':<38} |       | {wall:6.1f} | {cpu:20.1f} |")
    t = res.timings
    print(
        f"demo's own figures: plan {t['plan_s']:.1f} s, calibration "
        f"{t.get('calibration_s', 0.0):.1f} s, run {t['run_s']:.1f} s, total {t['total_s']:.1f} s"
    )
    if res.calibration is not None and res.calibration.tour_note:
        print(f"calibration tour: {res.calibration.tour_note}")
    speed = DemoOptions().calibration_speed
    for run in _runs:
        caps = run.captures  # type: ignore[attr-defined]
        print(
            "calibration tour walls: "
            + ", ".join(f"{k} {v:.1f} s" for k, v in caps.wall_s.items())
            + f"; robot time {caps.robot_time_s:.0f} s, at {speed:g}x: "
            f"{caps.robot_time_s / speed:.0f} s of wall at least"
        )
    laps: dict[str, float] = defaultdict(float)
    for h in res.run.hole_timings:
        for k, v in h.items():
            laps[k] += v
    if laps:
        print("run, summed over holes: " + ", ".join(f"{k} {v:.1f} s" for k, v in laps.items()))
    print(f"(load average {load:.1f} on {os.cpu_count()} cores)")
    ok = wall <= TARGET_S
    print(f"target ≤ {TARGET_S:.0f} s wall: {'PASS' if ok else 'FAIL'} ({wall:.1f} s)")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
