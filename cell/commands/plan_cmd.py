"""``holecell plan [CELL] -o tour.json``: plan the inspection tour of a cell.

Reads CELL (a cell.yaml; default: the built-in motorcycle frame), plans the
tour (viewpoints, sequence, paths, timing) and writes ``tour.json``. Shows a
progress bar per stage on stderr and prints a summary on stdout.
"""

from __future__ import annotations

import argparse
import gc
import sys
import time
from pathlib import Path
from typing import TextIO

from cell.commands.argtypes import positive_int
from cell.config import load_cell
from cell.errors import CellError
from planner import STAGES, Options, Tour, TourPlanner
from planner.engines import Engine, make_engine
from planner.errors import OptionsError
from planner.multistart import DEFAULT_STARTS, plan_multistart
from planner.sequence import SEQUENCERS


class StageBars:
    """One text progress bar per planner stage (a line each; redrawn in place on a terminal)."""

    WIDTH = 30

    def __init__(self, stream: TextIO = sys.stderr) -> None:
        self.stream = stream
        self.tty = stream.isatty()
        self.stage: str | None = None
        self.started = time.perf_counter()
        self.last_draw = 0.0

    def _draw(self, stage: str, done: int, total: int, final: bool) -> None:
        frac = done / total if total else 1.0
        bar = "#" * round(frac * self.WIDTH)
        elapsed = time.perf_counter() - self.started
        line = f"{stage:<11s} [{bar:<{self.WIDTH}s}] {done}/{total}  {elapsed:5.2f} s"
        if 0 < done < total:  # at this stage's pace so far
            line += f"  ETA {elapsed / done * (total - done):4.0f} s"
        if self.tty:
            self.stream.write("\r" + line + ("\n" if final else ""))
        elif final:
            self.stream.write(line + "\n")
        self.stream.flush()

    def __call__(self, stage: str, done: int, total: int) -> None:
        if stage != self.stage:
            self.stage = stage
            self.started = time.perf_counter()
        now = time.perf_counter()
        final = done >= total
        if final or now - self.last_draw > 0.05:
            self.last_draw = now
            self._draw(stage, done, total, final)


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``plan`` subcommand."""
    p = sub.add_parser(
        "plan",
        help="plan the inspection tour of a cell and write tour.json",
        description=(
            "Reads CELL (a cell.yaml; default: the built-in motorcycle frame) and writes the "
            "inspection tour to OUT (tour.json): the hole order, the joint configuration at each "
            "stop, the jerk-limited trajectory sampled at the controller period, the cycle time "
            "and the holes left out with their reasons. Units: m, rad, s."
        ),
    )
    p.add_argument("cell", nargs="?", default=None, help="cell file (default: built-in)")
    p.add_argument(
        "-o", "--output", default="tour.json", help="tour file to write (default: %(default)s)"
    )
    p.add_argument("--strict", action="store_true", help="fail if any hole cannot be inspected")
    p.add_argument(
        "--seed", type=int, default=0, help="random seed; same seed, same tour (default: 0)"
    )
    p.add_argument(
        "--time-budget",
        type=float,
        default=None,
        metavar="S",
        help="cap on the sequencer's search time in s (default: 1 s + 0.015 s per hole)",
    )
    p.add_argument(
        "--roll-step-deg", type=float, default=15.0, help="roll sampling about the view axis"
    )
    p.add_argument("--tilt-deg", type=float, default=0.0, help="half-angle of the view tilt cone")
    p.add_argument(
        "--fallback-tilt-deg",
        type=float,
        default=10.0,
        help="tilt cone tried for a hole with no free view along its axis (0 = never)",
    )
    p.add_argument("--dt", type=float, default=0.004, help="controller period in s")
    p.add_argument("--dwell", type=float, default=0.2, help="rest at each stop in s")
    p.add_argument("--quiet", action="store_true", help="no progress bars")
    add_engine_arguments(p)
    p.set_defaults(handler=run_plan)


def add_engine_arguments(p: argparse.ArgumentParser) -> None:
    """The multi-start and engine options shared by ``plan`` and ``plan-batch``."""
    p.add_argument(
        "--starts",
        type=positive_int,
        default=DEFAULT_STARTS,
        help="independent starts (seeds SEED*N .. SEED*N+N-1), the best tour kept "
        "(default: %(default)s; 1 plans in this process with per-stage progress bars)",
    )
    p.add_argument(
        "--jobs",
        type=positive_int,
        default=None,
        help="local processes running the starts (default: every core)",
    )
    p.add_argument(
        "--ray",
        metavar="ADDRESS",
        default=None,
        help="run the starts on the Ray cluster at ADDRESS ('local': a local Ray instance; "
        "needs the [ray] extra)",
    )
    p.add_argument(
        "--sequencer",
        choices=SEQUENCERS,
        default=Options().sequencer,
        help="GTSP solver (default: %(default)s)",
    )


def _options(args: argparse.Namespace) -> Options:
    return Options(
        roll_step_deg=args.roll_step_deg,
        tilt_deg=args.tilt_deg,
        fallback_tilt_deg=args.fallback_tilt_deg,
        strict=args.strict,
        seed=args.seed,
        time_budget_s=args.time_budget,
        dt=args.dt,
        dwell_s=args.dwell,
        sequencer=args.sequencer,
    )


def engine_for(args: argparse.Namespace) -> Engine | None:
    """The engine of the starts, or None to plan a single start in this process."""
    if args.ray is None and args.starts == 1:
        return None
    return make_engine(args.ray, args.jobs)


def plan_cell(
    cell: object, options: Options, args: argparse.Namespace, engine: Engine | None
) -> Tour:
    """Plan one cell: in this process (one start, stage bars) or multi-start on ``engine``."""
    if engine is None:
        progress = None if args.quiet else StageBars()
        if getattr(cell, "reference_markers", None):  # viewpoints that see the markers
            from cell.camera import cell_stereo
            from cell.referencing.viewpoints import MarkerAwarePlanner

            return MarkerAwarePlanner(cell, cell_stereo(cell), options, progress).plan(cell)
        return TourPlanner(options, progress).plan(cell)
    if not args.quiet:
        print(f"planning {args.starts} start(s) on {engine.name} ...", file=sys.stderr)
    return plan_multistart(cell, options, args.starts, engine)


def summary(tour: Tour, path: Path) -> list[str]:
    """Human-readable summary lines of a planned tour."""
    lines = [
        f"cell          {tour.cell_name}  (sha256 {tour.cell_sha256[:12]}...)",
        f"holes         {len(tour.stops)} in the tour, {len(tour.left_out)} left out",
    ]
    lines += [f"  left out    {h.hole_id}: {h.reason}" for h in tour.left_out]
    stages = "  ".join(f"{s} {tour.timings_s.get(s, 0.0):.2f}" for s in STAGES)
    lines += [
        f"cycle time    {tour.cycle_time_s:.2f} s  "
        f"(dwell {tour.settings.get('dwell_s', 0.0)} s per stop)",
        f"planning time {tour.planning_time_s:.2f} s  ({stages} s)",
        f"trajectory    {len(tour.trajectory)} samples every {tour.dt * 1e3:g} ms, "
        f"{tour.settings.get('ompl_segments', 0)} segment(s) planned around obstacles",
        f"written       {path}",
    ]
    if "start_cycle_times_s" in tour.settings:
        times = ", ".join(
            "failed" if c is None else f"{c:.2f}" for c in tour.settings["start_cycle_times_s"]
        )
        seeds = tour.settings["start_seeds"]
        lines.insert(
            -1,
            f"starts        {len(seeds)} on {tour.settings['engine']}: cycle {times} s "
            f"(seeds {seeds[0]}..{seeds[-1]}; kept seed {tour.settings['seed']})",
        )
    return lines


def run_plan(args: argparse.Namespace) -> int:
    """Plan and write the tour; exit 0 (complete), 1 (holes left out) or 2 (error)."""
    out = Path(args.output)
    if out.is_dir():
        raise CellError(f"-o {out}: is a directory; give a file name such as tour.json")
    if not out.parent.exists():
        raise CellError(f"-o {out}: folder {out.parent} does not exist")
    try:
        options = _options(args)
    except OptionsError as exc:
        raise CellError(str(exc)) from exc
    cell = load_cell(args.cell)
    tour = plan_cell(cell, options, args, engine_for(args))
    gc.collect()  # free the OMPL objects now (their bindings complain if still alive at exit)
    tour.save(out)
    print("\n".join(summary(tour, out)))
    return 1 if tour.left_out else 0
