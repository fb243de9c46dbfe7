"""``holecell report RUN_DIR``: write report.json and report.csv of a run and print a summary."""

from __future__ import annotations

import argparse

from cell.review.report import format_summary, write_report


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``report``."""
    p = sub.add_parser(
        "report",
        help="write a run's report.json, report.csv, report.html and report.qif; print its summary",
        description=(
            "Reads RUN_DIR/results.sqlite (never modifies it) and writes RUN_DIR/report.json "
            "(summary, every hole, every event; SI units) and RUN_DIR/report.csv (one row per "
            "characteristic, as the HTML: value, tolerance, limits, U, decision; m at 0.01 um) and "
            "RUN_DIR/report.html (the inspection protocol: header, hole table with U and the "
            "ISO 14253-1 decision, plots; self-contained) and RUN_DIR/report.qif (QIF 3.0 "
            "results, validated against the vendored QIF schemas; docs/qif.md)."
        ),
    )
    p.add_argument("run_dir", help="a run directory (holds results.sqlite)")
    p.add_argument("--operator", default="", help="name for the report's operator field")
    p.set_defaults(handler=run_report)


def run_report(args: argparse.Namespace) -> int:
    """Handler of ``holecell report``."""
    summ = write_report(args.run_dir, args.operator)
    print(format_summary(summ))
    print(f"wrote {args.run_dir}/report.json, report.csv, report.qif and report.html")
    return 0
