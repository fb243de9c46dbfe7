"""``holecell spc RUN_DIR...``: SPC across runs (spc.csv, spc.html) from their report.qif."""

from __future__ import annotations

import argparse
from pathlib import Path

from cell.review.spc.collect import read_runs, series
from cell.review.spc.errors import SpcError
from cell.review.spc.write import Analysis, analyse, write_spc


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``spc``."""
    p = sub.add_parser(
        "spc",
        help="statistics across runs: I-MR charts and Cp/Cpk per characteristic",
        description=(
            "Reads the report.qif of every RUN_DIR (or of every run folder inside a folder "
            "given), validated against the QIF 3.0 schemas, and writes OUT/spc.csv (per "
            "characteristic: n, mean, overall s, moving-range sigma MR-bar/1.128, control "
            "limits, tolerance limits, Cp, Cpk, Pp, Ppk, for positions the percentile Cpk of a "
            "Rice fit, runs out of control; SI units) and "
            "OUT/spc.html (the same table with individuals and moving-range charts)."
        ),
    )
    p.add_argument("run_dirs", nargs="+", metavar="RUN_DIR", help="run directories or folders")
    p.add_argument(
        "--out",
        default=None,
        help="output folder (default: the one RUN_DIR or folder given; else .)",
    )
    p.set_defaults(handler=run_spc)


#: characteristics named in the summary line of those without statistics (then "...")
MAX_NAMED = 4


def _names(results: list[Analysis]) -> str:
    names = [a.series.name for a in results]
    more = ", ..." if len(names) > MAX_NAMED else ""
    return ", ".join(names[:MAX_NAMED]) + more


def run_spc(args: argparse.Namespace) -> int:
    """Handler of ``holecell spc``: exit 0 when at least one characteristic has statistics;
    exit 2 (a refusal, nothing written) when none has: no characteristics in the runs, or
    none evaluated in two runs (a single run given)."""
    runs = read_runs(args.run_dirs)
    results = analyse(series(runs))
    where = str(Path(runs[0].path).parent) if len(runs) == 1 else f"{len(runs)} runs"
    if not results:
        raise SpcError(
            f"{where}: the report.qif carry no characteristics (no drawing tolerances "
            "evaluated): nothing to chart"
        )
    done = [a for a in results if a.cap is not None]
    undone = [a for a in results if a.cap is None]
    if not done:
        raise SpcError(
            f"{where}: statistics need a characteristic evaluated in two runs or more; none "
            f"of the {len(results)} is (give more run directories, or a folder of runs)"
        )
    out = args.out or (args.run_dirs[0] if len(args.run_dirs) == 1 else ".")
    csv_path, html_path = write_spc(results, [str(Path(r.path).parent) for r in runs], out)
    why = f" (evaluated in fewer than two runs: {_names(undone)})" if undone else ""
    print(
        f"{len(runs)} runs, {len(results)} characteristics: statistics for {len(done)}, "
        f"not for {len(undone)}{why}"
    )
    for a in done:
        s, cap = a.series, a.cap
        cpk = "-" if cap.cpk is None else f"{cap.cpk:.2f}"
        print(
            f"  {s.name:<22} n {cap.n:3d}  Cpk {cpk:>6}  out of control {len(cap.out_of_control)}"
        )
        if cap.cpk is not None and not cap.enough_for_capability:
            print(f"    warning: {cap.capability_note()}")
    print(f"wrote {csv_path} and {html_path}")
    return 0
