"""``holecell calibrate``: the calibrations, one subcommand module each.

``calibrate stereo`` (:mod:`cell.commands.calibrate_stereo_cmd`) calibrates the stereo head;
``calibrate hand-eye`` (:mod:`cell.commands.calibrate_handeye_cmd`) the head on the flange,
the target in the base, the arm's D-H errors and the stereo extrinsics from recorded data;
``calibrate cell`` (:mod:`cell.commands.calibrate_cell_cmd`) the same by running the calibration
tour in the cell; ``calibrate example`` (:mod:`cell.commands.calibrate_example_cmd`) writes a
synthetic set of such data to try it on. The older form ``holecell calibrate --left ... --right
...`` is the stereo calibration.
A new calibration is one more module in :data:`CALIBRATE_MODULES` with a ``register(sub)``.
"""

from __future__ import annotations

import argparse
import importlib

from cell.commands import calibrate_stereo_cmd
from cell.commands.errors import CalibrateUsageError

#: the ``calibrate`` subcommands' modules under ``cell.commands``, in ``--help`` order
CALIBRATE_MODULES: tuple[str, ...] = (
    "calibrate_stereo_cmd",
    "calibrate_handeye_cmd",
    "calibrate_cell_cmd",
    "calibrate_example_cmd",
)


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``calibrate`` subcommand and its own subcommands."""
    p = sub.add_parser(
        "calibrate",
        help="calibrations: stereo head (stereo), hand-eye and kinematics (hand-eye, cell), "
        "a set to try them (example)",
        description=(
            "Calibrations from images of a plate target. 'calibrate stereo' calibrates the "
            "stereo head; 'calibrate hand-eye' the head on the flange, the target in the base, "
            "the arm's D-H errors and the stereo extrinsics from images and robot poses "
            "recorded elsewhere; 'calibrate cell' the same by running the calibration tour on "
            "the controller and the head; 'calibrate example DIR' writes a synthetic set to try "
            "it on. Without a subcommand, --left/--right run the stereo "
            "calibration (the older form): " + calibrate_stereo_cmd.DESCRIPTION
        ),
    )
    calibrate_stereo_cmd.add_arguments(p, required=False)
    inner = p.add_subparsers(dest="calibrate_command", metavar="WHAT")
    for name in CALIBRATE_MODULES:
        importlib.import_module(f"cell.commands.{name}").register(inner)
    p.set_defaults(handler=_older_form)


def _older_form(args: argparse.Namespace) -> int:
    """``holecell calibrate --left ... --right ...``: the stereo calibration."""
    missing = [
        f"--{name}"
        for name in ("left", "right", "cols", "rows", "pitch")
        if getattr(args, name) is None
    ]
    if missing:
        raise CalibrateUsageError(
            "give a subcommand (stereo, hand-eye, cell, example) or the stereo calibration's "
            "options; missing: " + ", ".join(missing)
        )
    return calibrate_stereo_cmd.run(args)
