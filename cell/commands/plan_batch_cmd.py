"""``holecell plan-batch CELL... -o DIR``: plan many cells (part variants) on one engine.

Each cell's tour goes to ``DIR/<cell file stem>.tour.json``; ``DIR/summary.csv`` has a
row per cell (status, holes, cycle time, planning time, error) and is rewritten after
every cell, so a killed batch leaves a summary of what it finished. A cell whose file
cannot be read or whose planning fails is listed as ``failed`` with the message and the
batch goes on. Run again with the same arguments and finished cells are skipped: a tour
is reused when it was planned for exactly that cell file (robot, name and SHA-256 of the
text, :func:`planner.check_tour_for_cell`) with the same options, so after a fixture
change only the cells whose files changed are planned again.
"""

from __future__ import annotations

import argparse
import csv
import gc
import sys
import time
from dataclasses import dataclass
from pathlib import Path

from cell.commands.plan_cmd import _options, add_engine_arguments, engine_for, plan_cell
from cell.config import load_cell
from cell.errors import CellError
from planner import load_tour
from planner.engines import make_engine
from planner.errors import OptionsError, PlanningError, TourCellMismatchError
from planner.planner import check_tour_for_cell

COLUMNS = (
    "cell_file",
    "cell_name",
    "status",
    "planned",
    "holes",
    "left_out",
    "cycle_time_s",
    "planning_time_s",
    "tour_file",
    "error",
)
#: options that must match for a finished tour to be reused
REUSE_KEYS = ("seed", "roll_step_deg", "tilt_deg", "strict", "dt", "dwell_s", "sequencer")


@dataclass
class Row:
    """One line of summary.csv."""

    cell_file: str
    cell_name: str = ""
    status: str = "failed"
    planned: str = ""
    holes: int | str = ""
    left_out: int | str = ""
    cycle_time_s: float | str = ""
    planning_time_s: float | str = ""
    tour_file: str = ""
    error: str = ""


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``plan-batch`` subcommand."""
    p = sub.add_parser(
        "plan-batch",
        help="plan many cells (part variants) into one folder, with a summary CSV",
        description=(
            "Plans every CELL (cell.yaml files, e.g. the variants of a product family) on one "
            "engine and writes DIR/<cell>.tour.json for each and DIR/summary.csv. Failures "
            "are listed and the batch goes on; run it again to resume (finished cells whose "
            "file and options are unchanged are skipped). Units: m, rad, s."
        ),
    )
    p.add_argument("cells", nargs="+", metavar="CELL", help="cell files")
    p.add_argument("-o", "--output", required=True, metavar="DIR", help="folder for the tours")
    p.add_argument("--seed", type=int, default=0, help="base seed of every cell (default: 0)")
    p.add_argument("--strict", action="store_true", help="a cell with unreachable holes fails")
    p.add_argument("--time-budget", type=float, default=None, metavar="S")
    p.add_argument("--roll-step-deg", type=float, default=15.0)
    p.add_argument("--tilt-deg", type=float, default=0.0)
    p.add_argument("--fallback-tilt-deg", type=float, default=10.0)
    p.add_argument("--dt", type=float, default=0.004)
    p.add_argument("--dwell", type=float, default=0.2)
    p.add_argument("--force", action="store_true", help="plan every cell again")
    add_engine_arguments(p)
    p.set_defaults(handler=run_plan_batch, quiet=True)


def _tour_path(out: Path, cell_file: Path) -> Path:
    return out / f"{cell_file.stem}.tour.json"


def _reusable(path: Path, cell: object, settings: dict) -> bool:
    if not path.exists():
        return False
    try:
        tour = load_tour(path)
        check_tour_for_cell(tour, cell)
    except (PlanningError, TourCellMismatchError):
        return False
    same = all(tour.settings.get(k) == settings[k] for k in REUSE_KEYS if k != "seed")
    base = tour.settings.get("multistart_base_seed", tour.settings.get("seed"))
    return (
        same and base == settings["seed"] and tour.settings.get("starts", 1) == settings["starts"]
    )


def _row_of(path: Path, cell_file: Path, planned: str) -> Row:
    tour = load_tour(path)
    return Row(
        str(cell_file),
        tour.cell_name,
        tour.status,
        planned,
        len(tour.stops),
        len(tour.left_out),
        round(tour.cycle_time_s, 4),
        round(tour.planning_time_s, 3),
        str(path),
    )


def write_summary(out: Path, rows: list[Row]) -> Path:
    """Write ``summary.csv`` (via a temporary file)."""
    path = out / "summary.csv"
    tmp = path.with_name(path.name + ".tmp")
    with tmp.open("w", newline="") as f:
        w = csv.writer(f)
        w.writerow(COLUMNS)
        for r in rows:
            w.writerow([getattr(r, c) for c in COLUMNS])
    tmp.replace(path)
    return path


def run_plan_batch(args: argparse.Namespace) -> int:
    """Plan every cell; exit 0 (all complete), 1 (holes left out or cells failed), 2 (usage)."""
    out = Path(args.output)
    if out.exists() and not out.is_dir():
        raise CellError(f"-o {out}: is a file; give a folder")
    out.mkdir(parents=True, exist_ok=True)
    files = [Path(c) for c in args.cells]
    stems = [f.stem for f in files]
    dup = sorted({s for s in stems if stems.count(s) > 1})
    if dup:
        raise CellError(f"cells with the same file name would share a tour file: {dup[0]}")
    try:
        options = _options(args)
    except OptionsError as exc:
        raise CellError(str(exc)) from exc
    # always worker processes: a start's tour then depends on its seed alone (OMPL seeds once
    # per process), not on the cells planned before it in this process
    engine = engine_for(args) or make_engine(None, args.jobs)
    settings = options.to_dict() | {"starts": args.starts}
    rows: list[Row] = []
    for i, cell_file in enumerate(files):
        path = _tour_path(out, cell_file)
        started = time.perf_counter()
        try:
            cell = load_cell(cell_file)
            if not args.force and _reusable(path, cell, settings):
                rows.append(_row_of(path, cell_file, "earlier"))
                status = "skipped (finished earlier)"
            else:
                tour = plan_cell(cell, options, args, engine)
                gc.collect()
                tour.save(path)
                rows.append(_row_of(path, cell_file, "now"))
                status = f"{tour.status}, cycle {tour.cycle_time_s:.2f} s"
        except (CellError, PlanningError, OSError) as exc:
            rows.append(Row(str(cell_file), error=str(exc).replace("\n", " ")))
            status = f"failed: {exc}"
        write_summary(out, rows)
        took = time.perf_counter() - started
        print(f"[{i + 1}/{len(files)}] {cell_file}: {status} ({took:.1f} s)", file=sys.stderr)
    summary = write_summary(out, rows)
    failed = [r for r in rows if r.status == "failed"]
    partial = [r for r in rows if r.status == "partial"]
    print(
        f"{len(rows)} cell(s): {len(rows) - len(failed) - len(partial)} complete, "
        f"{len(partial)} with holes left out, {len(failed)} failed; summary {summary}"
    )
    for r in failed:
        print(f"  failed  {r.cell_file}: {r.error}")
    return 1 if failed or partial else 0
