"""Where the demo's time goes, by stage: ``holecell demo`` run in this process, timed.

Runs :func:`cell.demo.demo.run_demo` (the built-in cell, the default options, no recording)
with timers around its stages and their main parts, and prints per stage the wall time and,
where the work runs in this process, its CPU time (the thread that ran it), then the demo's own
figures (the calibration tour's cache use, the calibration's move / capture / detect / solve
walls, the survey's, the run's per-hole laps). Planning runs the reference, calibration and
survey tours in worker processes: their time shows as the wait for them (``plan: wait for
workers``). The survey renders and detects its views in worker processes while the arm moves:
their wall and CPU time, summed over the views, are the workers' own figures
(``survey: render (workers)``, ``survey: detect (workers)``); the capture loop's wall is the
stage the survey's wall time is made of (``survey: tour driven``).

The calibration tour renders and detects its views in worker processes as the survey does (its
walls: ``calibration tour walls``), and its adjustment runs in a worker while the survey is
driven (``calibration: wait for the solve (worker)``: what is left of it after the survey); the
run renders each stop's pair in a worker while it
measures the stop before (its wait for a pair: ``render_s`` of the holes' laps). Renders left in
this process are split by phase, and so is the marker detection (the reference rounds' and the
holes').

Targets (issue 27): the demo in ≤ 60 s wall on the 2-core machine. On a shared machine
wall times include waiting for a CPU; the load average is printed.

Run: ``.venv/bin/python benchmarks/profile_demo.py`` (a full demo, referenced: minutes),
``--no-referencing`` (the holes carried by the arm: no survey) or ``--quick``
(``--calibration-method projected``: no calibration tour driven).
"""

from __future__ import annotations

import argparse
import functools
import importlib
import os
import sys
import tempfile
import threading
import time
from collections import defaultdict
from pathlib import Path

import cell.calibration.capture as capture
import cell.demo.calibrate as demo_calibrate
import cell.demo.demo as demo
import cell.run.inspect as inspect_hole
import cell.run.reference_phase as reference_phase
import cell.run.runner as runner
import cell.sim.camera as sim_camera
import planner.planner as tour_planner
from cell.commands.demo_cmd import format_calibration, format_demo, format_survey
from cell.demo.demo import DemoOptions, run_demo

# (cell.referencing exports a function named survey: the module by its full name)
survey_run = importlib.import_module("cell.referencing.survey.run")

TARGET_S = 60.0
#: (label, owner, attribute): the functions timed, in the order printed
TIMED = (
    ("plan: all tours", demo, "plan_demo"),
    ("plan: hole tour (this process)", tour_planner.TourPlanner, "plan"),
    ("calibration: all", demo, "_calibration"),
    ("calibration: tour driven (move, render, detect)", capture, "capture_calibration_tour"),
    ("calibration: wait for the solve (worker)", demo_calibrate.PendingCalibration, "finish"),
    ("survey: all", demo, "_survey"),
    ("survey: tour driven (move, render, detect)", survey_run, "SurveyCapture"),
    ("survey: adjust", survey_run, "survey"),
    ("run: all", demo, "_run_sim"),
    ("run: runner set-up (stops corrected)", runner.Runner, "__init__"),
    ("run: reference rounds", runner.Runner, "_reference_phase"),
    ("run: thermal identification", runner.Runner, "_identify"),
    ("run: marker detect (reference rounds)", reference_phase, "detect_pair"),
    ("run: marker detect (holes)", runner, "detect_pair"),
    ("run: resection", runner, "locate_stop"),
    ("run: inspect a hole (measure, budget)", runner, "inspect_hole"),
    ("run: measure a hole (measure_hole)", inspect_hole, "measure_hole"),
    ("report: protocol", demo, "write_report"),
    ("report: errors vs truth", demo, "datum_truth_error"),
)

#: the demo's phases: a render is counted in the phase it happens in
PHASES = {"calibration: all": "calibration", "survey: all": "survey", "run: all": "run"}
RENDER = ("camera: render a pair", sim_camera.SimCamera, "capture")
_phase = ["plan"]

_lock = threading.Lock()
_wall: dict[str, float] = defaultdict(float)
_cpu: dict[str, float] = defaultdict(float)
_calls: dict[str, int] = defaultdict(int)
_runs: list[object] = []


def _add(label: str, wall: float, cpu: float, calls: int = 1) -> None:
    with _lock:
        _wall[label] += wall
        _cpu[label] += cpu
        _calls[label] += calls


def _timed(label: str, fn):
    @functools.wraps(fn)
    def wrapper(*args, **kwargs):
        key = f"{_phase[0]}: render a pair" if label == RENDER[0] else label
        before = _phase[0]
        if label in PHASES:
            _phase[0] = PHASES[label]
        t, c = time.perf_counter(), time.thread_time()
        try:
            out = fn(*args, **kwargs)
        finally:
            _add(key, time.perf_counter() - t, time.thread_time() - c)
            _phase[0] = before
        if label.startswith("calibration: tour"):
            _runs.append(out)  # a CapturedTour
        return out

    return wrapper


class _TimedSurveyCapture(survey_run.SurveyCapture):
    """The survey's capture loop, timed as a whole; its captures' figures kept (the workers'
    render and detection)."""

    def run(self):  # type: ignore[override]
        out = _timed("survey: tour driven (move, render, detect)", super().run)()
        _survey.append(out)
        return out


_survey: list[object] = []


def _install() -> None:
    for label, owner, name in (*TIMED, RENDER):
        if not hasattr(owner, name):  # the code moved on: say so, time the rest
            print(f"(not timed: {label}: {getattr(owner, '__name__', owner)}.{name} is gone)")
            continue
        if name == "SurveyCapture":
            setattr(owner, name, _TimedSurveyCapture)
        else:
            setattr(owner, name, _timed(label, getattr(owner, name)))


def main(argv: list[str] | None = None) -> int:
    """Run one demo and print the table; exit code 1 when its wall time misses the target."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="projected calibration (no tour driven)")
    ap.add_argument("--no-referencing", action="store_true", help="no survey: the arm's chain")
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args(argv)
    _install()
    method = "projected" if args.quick else "images"
    load0 = os.getloadavg() if hasattr(os, "getloadavg") else (float("nan"),) * 3
    c0, t0 = time.process_time(), time.perf_counter()
    opts = DemoOptions(
        seed=args.seed, calibration_method=method, referencing=not args.no_referencing
    )
    refused = ""
    with tempfile.TemporaryDirectory() as tmp:
        try:
            res = run_demo(Path(tmp) / "run", opts)
        except Exception as exc:  # a refusal (e.g. the survey's): the stages so far
            res, refused = None, f"{type(exc).__name__}: {exc}"
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    for caps in _survey:  # the workers' figures, summed over the views
        w = caps.wall_s  # type: ignore[attr-defined]
        n = len(caps.views)  # type: ignore[attr-defined]
        _add("survey: render (workers)", w.get("render_s", 0.0), float("nan"), n)
        _add("survey: detect (workers)", w.get("detect_s", 0.0), float("nan"), n)
        _add("survey: render + detect CPU (workers)", float("nan"), w.get("cpu_s", 0.0), n)
    ref = "no referencing" if args.no_referencing else "referenced"
    print(f"holecell demo, seed {args.seed}, calibration {method}, {ref}: by stage (s)")
    print(f"| {'stage':<44} | calls | wall s | cpu s (its thread) |")
    print(f"|{'-' * 46}|-------|--------|--------------------|")
    labels = [label for label, _, _ in TIMED]
    for phase in ("calibration", "survey", "run"):  # each phase's renders after its total
        at = labels.index(f"{phase}: all") + 1
        labels.insert(at, f"{phase}: render a pair")
    at = labels.index("survey: adjust")
    labels[at:at] = ["survey: render (workers)", "survey: detect (workers)",
                     "survey: render + detect CPU (workers)"]  # fmt: skip
    for label in labels:
        if _calls[label]:
            print(f"| {label:<44} | {_calls[label]:5d} | {_wall[label]:6.1f} "
                  f"| {_cpu[label]:18.1f} |".replace(" nan |", "   - |"))  # fmt: skip
    waited = _wall["plan: all tours"] - _wall["plan: hole tour (this process)"]
    print(f"| {'plan: wait for workers':<44} |       | {waited:6.1f} |                    |")
    print(f"| {'total (cpu: this process)':<44} |       | {wall:6.1f} | {cpu:18.1f} |")
    if res is not None:
        t = res.timings
        print(
            f"demo's own figures: plan {t['plan_s']:.1f} s, calibration "
            f"{t.get('calibration_s', 0.0):.1f} s, survey {t.get('survey_s', 0.0):.1f} s, "
            f"run {t['run_s']:.1f} s, total {t['total_s']:.1f} s"
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
    for caps in _survey:
        print(
            "survey tour walls: "
            + ", ".join(f"{k} {v:.1f} s" for k, v in caps.wall_s.items())  # type: ignore[attr-defined]
            + f"; {len(caps.views)} views, robot time {caps.robot_time_s:.0f} s"  # type: ignore[attr-defined]
        )
    if res is not None:
        laps: dict[str, float] = defaultdict(float)
        for h in res.run.hole_timings:
            for k, v in h.items():
                laps[k] += v
        if laps:
            print("run, summed over holes: " + ", ".join(f"{k} {v:.1f} s" for k, v in laps.items()))
        print("the demo's figures (as holecell demo prints them):")
        print(format_calibration(res))
        print(format_survey(res))
        print(format_demo(res))
    else:
        print(f"the demo was refused: {refused}")
    print(f"(load average {load0[0]:.1f} at the start, {load:.1f} at the end, on "
          f"{os.cpu_count()} cores)")  # fmt: skip
    ok = wall <= TARGET_S and res is not None
    print(f"target ≤ {TARGET_S:.0f} s wall: {'PASS' if ok else 'FAIL'} ({wall:.1f} s)")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
