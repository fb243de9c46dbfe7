"""``holecell remeasure RUN_DIR``: measure a run's kept stereo pairs again into a new run."""

from __future__ import annotations

import argparse
import time
from pathlib import Path


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``remeasure``."""
    p = sub.add_parser(
        "remeasure",
        help="measure a run's kept stereo pairs again with today's code, into a new run",
        description=(
            "Reads RUN_DIR (results.sqlite and the stereo pairs the run kept in RUN_DIR/images) "
            "and measures every hole again with today's code, the joints, temperatures, thermal "
            "model, cell calibration and part temperature stored with the run, and the cell's "
            "stereo calibration or --stereo (a corrected one). Writes a new run directory OUT "
            "(results.sqlite and the reports) and never modifies RUN_DIR; prints each hole's "
            "stored and new position (ISO 1101, fixture frame) and diameter."
        ),
    )
    p.add_argument("run_dir", help="a run directory that kept its images (holecell run)")
    p.add_argument(
        "-o", "--out", default=None,
        help="new run directory (default: RUN_DIR-remeasured-YYYYmmdd-HHMMSS)",
    )  # fmt: skip
    p.add_argument("--stereo", metavar="STEREO.json", default=None,
                   help="stereo calibration to measure with (default: the cell's)")  # fmt: skip
    p.set_defaults(handler=run_remeasure)


def _line(old, new) -> str:
    def pos(r) -> str:
        d = r.position_deviation_m
        return "-" if d is None else f"⌀{2 * d * 1e3:.4f}"

    def dia(r) -> str:
        return "-" if r.diameter_m is None else f"{r.diameter_m * 1e3:.4f}"

    return (f"{new.hole_id:<8} {old.status:>10} -> {new.status:<10} position {pos(old)} -> "
            f"{pos(new)} mm, diameter {dia(old)} -> {dia(new)} mm")  # fmt: skip


def run_remeasure(args: argparse.Namespace) -> int:
    """Handler of ``holecell remeasure``."""
    from cell.review.report import format_summary, summary
    from cell.review.store import Store
    from cell.run.remeasure import remeasure

    src = Path(args.run_dir)
    out = Path(args.out) if args.out else src.with_name(
        f"{src.name}-remeasured-{time.strftime('%Y%m%d-%H%M%S')}")  # fmt: skip
    done = remeasure(src, out, args.stereo)
    for old, new in done.pairs:
        print(_line(old, new))
    if done.kept:
        print(f"kept as stored (no pair kept): {', '.join(done.kept)}")
    with Store.open(out) as store:
        print(format_summary(summary(store)))
    print(f"wrote {out} ({len(done.remeasured)} holes measured again); {src} unchanged")
    return 0
