"""The ``holecell`` command line: one subcommand module each under :mod:`cell.commands`.

User mistakes (every package's error base, and missing files) are printed as one
clear message on stderr with exit code 2, never as a traceback; so are mistakes on the command
line itself (argparse's usage block is left out: ``--help`` shows it).
"""

from __future__ import annotations

import argparse
import importlib
import logging
import os
import sys
from collections.abc import Sequence
from typing import NoReturn

#: subcommand modules under ``cell.commands``, in the order ``--help`` lists them
COMMAND_MODULES: tuple[str, ...] = (
    "cell_show",
    "thermal_cmd",
    "plan_cmd",
    "plan_batch_cmd",
    "plan_calibration_cmd",
    "measure_cmd",
    "calibrate_cmd",
    "run_cmd",
    "survey_cmd",
    "sim_cmd",
    "report_cmd",
    "demo_cmd",
    "truth_cmd",
    "spc_cmd",
    "import_step_cmd",
    "export_cmd",
    "controller_cmd",
    "remeasure_cmd",
)
#: the top-level command each module registers: ``holecell COMMAND ...`` imports only that
#: command's module (``holecell plan``: 0.74 s of imports instead of 1.2 s for them all);
#: ``--help``, no command or an unknown one import every module (a test holds this table
#: equal to what the modules register)
COMMAND_OF_MODULE: dict[str, str] = {
    "cell_show": "cell",
    "thermal_cmd": "thermal",
    "plan_cmd": "plan",
    "plan_batch_cmd": "plan-batch",
    "plan_calibration_cmd": "plan-calibration",
    "measure_cmd": "measure",
    "calibrate_cmd": "calibrate",
    "run_cmd": "run",
    "survey_cmd": "survey",
    "sim_cmd": "sim",
    "report_cmd": "report",
    "demo_cmd": "demo",
    "truth_cmd": "truth",
    "spc_cmd": "spc",
    "import_step_cmd": "import-step",
    "export_cmd": "export",
    "controller_cmd": "controller",
    "remeasure_cmd": "remeasure",
}


def _user_error_types() -> tuple[type[BaseException], ...]:
    from cell.errors import CellError
    from robots.errors import RobotModelError

    types: list[type[BaseException]] = [CellError, RobotModelError, FileNotFoundError]
    for module, name in (
        ("planner.errors", "PlanningError"),
        ("measure.errors", "MeasurementError"),
    ):
        try:
            types.append(getattr(importlib.import_module(module), name))
        except (ImportError, AttributeError):
            continue
    return tuple(types)


def _modules_for(argv: Sequence[str] | None) -> tuple[str, ...]:
    """The command modules to import for ``argv``: the named command's alone when known."""
    words = [a for a in argv or () if not a.startswith("-")]
    asked = words[0] if words else None
    mine = tuple(m for m in COMMAND_MODULES if COMMAND_OF_MODULE.get(m) == asked)
    return mine if asked is not None and len(mine) == 1 else COMMAND_MODULES


class OneLineParser(argparse.ArgumentParser):
    """An argument parser whose command-line errors are one line (exit 2), pointing at
    ``--help`` instead of printing the usage block; its subcommands' parsers are of this class
    too (``add_subparsers`` takes the parent's class)."""

    def error(self, message: str) -> NoReturn:
        """Print ``PROG: error: MESSAGE (see PROG --help)`` on stderr and exit 2."""
        self.exit(2, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


#: the exit codes every command uses (docs/conventions.md)
EXIT_CODES = """exit codes:
  0    success (holes out of tolerance still exit 0: the run worked)
  1    written, with something left out (a hole unreachable, holes left out of a tour)
  2    a user mistake or a refusal: one line on stderr naming the file, field and value
  130  interrupted (Ctrl-C); what was stored is kept"""


def build_parser(argv: Sequence[str] | None = None) -> argparse.ArgumentParser:
    """The argument parser with the subcommand ``argv`` names (every subcommand without one)."""
    parser = OneLineParser(
        prog="holecell",
        description="Robot-vision hole inspection cells: plan tours, run them, measure holes.",
        epilog=EXIT_CODES,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("-v", "--verbose", action="store_true", help="log progress details")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name in _modules_for(argv):
        importlib.import_module(f"cell.commands.{name}").register(sub)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``holecell`` console script; returns the exit code."""
    argv = sys.argv[1:] if argv is None else list(argv)
    parser = build_parser(argv)
    args = parser.parse_args(argv)
    logging.basicConfig(
        level=logging.INFO if args.verbose else logging.WARNING,
        format="%(levelname)s %(name)s: %(message)s",
    )
    if not getattr(args, "handler", None):
        parser.print_help()
        return 0 if args.command is None else 2
    try:
        return int(args.handler(args) or 0)
    except _user_error_types() as exc:
        print(f"holecell {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"holecell {args.command}: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:
        # the reader of stdout went away (``holecell ... | head``): stop quietly, as a process
        # killed by SIGPIPE would, and keep Python from failing again when it flushes stdout
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 141


if __name__ == "__main__":
    sys.exit(main())
