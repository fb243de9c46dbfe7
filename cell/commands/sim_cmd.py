"""``holecell sim [CELL]``: the simulated controller and stereo head, stand-alone.

For testing a cell computer (``holecell run``) against a simulated cell: prints the controller
port (a pty path or ``socket://127.0.0.1:PORT``) and the camera URL (``tcp://127.0.0.1:PORT``,
or ``gige://127.0.0.1,127.0.0.2``: two GigE Vision fake cameras), then serves until interrupted.
"""

from __future__ import annotations

import argparse
import time

from cell.commands.argtypes import (
    non_negative_float,
    non_negative_int,
    positive_float,
    probability,
)
from cell.commands.sim_gige import add_camera_arguments, serve_head
from cell.config import load_cell
from cell.errors import CellError
from cell.sim.faults import FaultPlan
from cell.sim.session import SimCell
from cell.sim.truth import CellTruth
from cell.sim.world import WorldOptions


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``sim``."""
    p = sub.add_parser(
        "sim",
        help="serve a simulated controller and stereo head for holecell run",
        description=(
            "Reads CELL (default: the built-in motorcycle frame) and serves the simulated "
            "controller (protocol of docs/protocol.md) on a pseudo-terminal or a local socket, "
            "and the simulated stereo head on a local TCP port. Prints both URLs; writes nothing."
        ),
    )
    p.add_argument("cell", nargs="?", default=None, help="cell file (default: built-in)")
    p.add_argument("--transport", choices=("pty", "socket"), default="pty")
    p.add_argument(
        "--controller",
        choices=("python", "rapid"),
        default="python",
        help="python: the Python stand-in; rapid: the shipped RAPID module in the interpreter",
    )
    p.add_argument(
        "--speed", type=positive_float, default=1.0, help="simulation speed (x real time, > 0)"
    )
    p.add_argument(
        "--drift-offset-s", type=non_negative_float, default=0.0, help="warm-up already elapsed (s)"
    )
    p.add_argument("--drop", type=probability, default=0.0, help="probability a frame is lost")
    p.add_argument("--corrupt", type=probability, default=0.0, help="probability of a flipped bit")
    p.add_argument("--delay", type=probability, default=0.0, help="probability an answer is late")
    p.add_argument(
        "--disconnect-after", type=non_negative_int, default=None, help="requests, then cut"
    )
    p.add_argument(
        "--estop-at",
        type=non_negative_int,
        default=None,
        help="e-stop on arrival at stop K (0-based)",
    )
    p.add_argument(
        "--missing", nargs="*", default=(), help="hole ids (of the cell) that are not there"
    )
    p.add_argument("--seed", type=int, default=0)
    p.add_argument(
        "--truth",
        metavar="TRUTH.yaml",
        default=None,
        help="every hidden error of the simulated cell (docs/calibration.md; fields left out "
        "are drawn from its seed, else --seed); default: no geometric error",
    )
    p.add_argument("--duration-s", type=positive_float, default=None, help="stop after this long")
    add_camera_arguments(p)
    p.set_defaults(handler=run_sim)


def run_sim(args: argparse.Namespace) -> int:
    """Handler of ``holecell sim``."""
    cell = load_cell(args.cell)
    known = {h.id for h in cell.part.holes}
    unknown = [h for h in args.missing if h not in known]
    if unknown:
        raise CellError(f"--missing: {cell.name} has no hole {', '.join(unknown)} "
                        f"(holes: {', '.join(sorted(known)[:8])}...)")  # fmt: skip
    faults = FaultPlan(
        drop=args.drop,
        corrupt=args.corrupt,
        delay=args.delay,
        disconnect_after=args.disconnect_after,
        estop_at_stop=args.estop_at,
        missing_holes=tuple(args.missing),
        seed=args.seed,
    )
    truth = (CellTruth.zero(args.seed) if args.truth is None
             else CellTruth.load(args.truth, cell, seed=args.seed))  # fmt: skip
    world = WorldOptions(speed=args.speed, drift_offset_s=args.drift_offset_s, truth=truth)
    with SimCell.start(cell, world, faults, args.transport, controller=args.controller) as sim:
        cam = serve_head(sim.camera, args)
        try:
            print(f"controller  {sim.url}", flush=True)
            print(f"camera      {cam.url}", flush=True)
            print("serving; Ctrl-C to stop", flush=True)
            t_end = None if args.duration_s is None else time.monotonic() + args.duration_s
            while t_end is None or time.monotonic() < t_end:
                time.sleep(0.2)
                if getattr(sim.controller, "error", None) is not None:  # the RAPID program
                    raise CellError(f"controller stopped: {sim.controller.error}")
        finally:
            cam.close()
    return 0
