"""``holecell truth draw [CELL] --seed N -o truth.yaml``: write a drawn simulated truth.

The file holds every hidden error of the simulated cell (:mod:`cell.sim.truth`), drawn from the
realistic distribution for seed N, so a benchmark or a user can see a draw, edit it and reuse it
with ``holecell sim --truth`` or ``holecell demo --truth``.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from cell.commands.argtypes import output_file
from cell.commands.group_help import help_handler
from cell.config import load_cell
from cell.errors import CellError


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``truth`` with its ``draw`` subcommand."""
    truth = sub.add_parser(
        "truth",
        help="write the simulated cell's hidden errors to a file",
        description="The simulated cell's truth file (docs/calibration.md, 'the simulated truth').",
    )
    truth_sub = truth.add_subparsers(dest="truth_command", metavar="ACTION")
    draw = truth_sub.add_parser(
        "draw",
        help="draw a realistic truth for a seed and write it",
        description=(
            "Draws every hidden error of the simulated cell (D-H errors, robot base, head on "
            "the flange, part and calibration target placement, repeatability, the head's "
            "calibration error, part temperature) from the realistic distribution of "
            "docs/calibration.md for --seed, and writes it as a truth file for "
            "holecell sim --truth / holecell demo --truth. CELL (default: built-in) gives the "
            "robot's data-sheet repeatability."
        ),
    )
    draw.add_argument("cell", nargs="?", default=None, help="cell file (default: built-in)")
    draw.add_argument("--seed", type=int, required=True, help="seed of the draw (>= 0)")
    draw.add_argument(
        "-o",
        "--output",
        type=output_file,
        required=True,
        metavar="FILE",
        help="truth file to write",
    )
    draw.add_argument("--force", action="store_true", help="overwrite FILE if it exists")
    draw.set_defaults(handler=run_draw)
    truth.set_defaults(handler=help_handler(truth))


def run_draw(args: argparse.Namespace) -> int:
    """Handler of ``holecell truth draw``."""
    from cell.sim.truth import CellTruth

    if args.seed < 0:
        raise CellError(f"--seed: {args.seed} must be >= 0")
    out = Path(args.output)
    if out.is_dir():
        raise CellError(f"{out}: is a directory, not a truth file")
    if out.exists() and not args.force:
        raise CellError(f"{out}: exists (--force to overwrite)")
    truth = CellTruth.drawn(args.seed, load_cell(args.cell))
    out.write_text(truth.to_yaml(), encoding="utf-8")
    print(f"wrote {out} (seed {args.seed})")
    return 0
