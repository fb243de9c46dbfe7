"""``holecell calibrate cell``: run the calibration tour in the cell and write ``cellcal.json``."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

DESCRIPTION = (
    "Runs the calibration tour (--tour caltour.json from holecell plan-calibration, or planned "
    "here: --views views of the cell's calibration_target) on the controller at --port and "
    "captures a stereo pair at each view from the head at --camera; detects the target in "
    "both images, then solves one least-squares adjustment of the reprojection errors of every "
    "view in both cameras for the hand-eye (the left camera's pose in tool0), the target in "
    "the robot base, the identifiable D-H errors of the arm and the stereo extrinsics, started "
    "from OpenCV's hand-eye. Prints every estimate with its standard deviation, the D-H terms "
    "the views cannot determine and why, the residuals, the robot time and the solve time; "
    "writes OUT (cellcal.json, docs/calibration.md) only when the calibration succeeds. "
    "Refuses (exit 2, one line, nothing written) a view without the target in either image, "
    "too few views, rotations about parallel axes and a tour planned for another cell."
)


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``calibrate cell`` to the ``calibrate`` subcommands."""
    from cell.commands.argtypes import non_negative_float, positive_int

    p = sub.add_parser(
        "cell",
        help="run the calibration tour in the cell: hand-eye, target, D-H errors, stereo",
        description=DESCRIPTION,
    )
    p.add_argument("cell", nargs="?", default=None, help="cell file (default: built-in)")
    p.add_argument("--port", required=True, help="controller port URL")
    p.add_argument("--camera", required=True, help="stereo head: tcp://HOST:PORT")
    p.add_argument(
        "--tour", type=Path, metavar="caltour.json", default=None,
        help="the calibration tour (default: plan one as plan-calibration does)",
    )  # fmt: skip
    p.add_argument("-o", "--output", default="cellcal.json", help="file to write (cellcal.json)")
    p.add_argument(
        "--views", type=positive_int, default=120,
        help="views of the tour planned without --tour (%(default)s)",
    )  # fmt: skip
    p.add_argument("--seed", type=int, default=0, help="seed of the tour planned without --tour")
    p.add_argument(
        "--settle-s", type=non_negative_float, default=0.2,
        help="wait after 'in position' before each capture, s (%(default)s)",
    )  # fmt: skip
    p.add_argument(
        "--max-edge-width", type=float, default=4.0, metavar="PX",
        help="widest edge (10-90 %% rise, px) of an image accepted as sharp (4)",
    )  # fmt: skip
    p.add_argument(
        "--fixed-stereo", action="store_true",
        help="take the stereo extrinsics from the stereo calibration as exact",
    )  # fmt: skip
    p.add_argument("--no-kinematics", action="store_true", help="do not estimate D-H errors")
    p.add_argument(
        "--fixed-intrinsics", action="store_true",
        help="take both cameras' lenses (fx, fy, cx, cy, distortion) from the stereo "
        "calibration as exact (default: estimate their corrections with the rest, "
        "marginalised; docs/calibration.md)",
    )  # fmt: skip
    p.add_argument(
        "--strict", action="store_true",
        help="refuse the whole tour when one image fails a quality check (default: drop that "
        "view with a warning and go on if the rest still determines the calibration)",
    )  # fmt: skip
    p.add_argument(
        "--max-warming-k", type=float, default=1.0, metavar="K",
        help="refuse the calibration when an arm temperature sensor changed by more than this "
        "over the tour (K; default %(default)s; warned over 0.3 K): a warming arm's growth is "
        "read as D-H errors (docs/calibration.md, 'A cold start')",
    )  # fmt: skip
    p.add_argument("--quiet", action="store_true", help="no progress lines")
    p.set_defaults(handler=run)


def _check_output(out: Path) -> None:
    from cell.errors import CellError

    if out.is_dir():
        raise CellError(f"-o {out}: is a directory; give a file name such as cellcal.json")
    if not out.parent.exists():
        raise CellError(f"-o {out}: folder {out.parent} does not exist")


def _progress(quiet: bool):
    def show(event: str, data: dict) -> None:
        if event == "dropped":
            print(data["warning"], file=sys.stderr, flush=True)
        elif event == "warming":
            print(data["line"], file=sys.stderr if data["line"].startswith("warning") else
                  sys.stdout, flush=True)  # fmt: skip
        elif event == "view":
            seen = "" if data["left"] and data["right"] else "  target NOT found"
            print(f"  view {data['k'] + 1}/{data['n']} {data['id']}{seen}", flush=True)
        elif event == "solve":
            print(f"solving {data['views']} views ...", flush=True)

    return None if quiet else show


def run(args: argparse.Namespace) -> int:
    """Handler: plan (or read) the tour, connect, run, solve, report, write."""
    from dataclasses import replace

    from cell.calibration.capture import (
        CalibrateCellOptions,
        CaptureSettings,
        check_calibration_tour,
        run_calibration_tour,
    )
    from cell.calibration.errors import CalibrationDataError
    from cell.calibration.estimate import SolveOptions
    from cell.calibration.file import save_calibration
    from cell.calibration.plan import calibrate_plan_options, plan_cell_calibration
    from cell.camera import NetworkCamera, cell_stereo
    from cell.commands.calibrate_report import print_result
    from cell.commands.controller_check import connect_checked
    from cell.config import load_cell
    from cell.link.client import ControllerClient
    from planner.calibration import load_caltour

    out = Path(args.output)
    _check_output(out)
    if not 0 < args.max_edge_width <= 50:
        raise CalibrationDataError("--max-edge-width", f"{args.max_edge_width:g} px not in (0, 50]")
    cell = load_cell(args.cell)
    stereo = cell_stereo(cell)
    if args.tour is not None:
        tour, source = load_caltour(args.tour), str(args.tour)
    else:
        print(f"planning {args.views} calibration views ...", flush=True)
        tour = plan_cell_calibration(cell, stereo, calibrate_plan_options(args.views, args.seed))
        source = f"the planned calibration tour ({args.views} views)"
    check_calibration_tour(cell, tour, source)  # before the arm moves
    options = CalibrateCellOptions(
        capture=CaptureSettings(
            settle_s=args.settle_s, max_edge_width_px=args.max_edge_width, strict=args.strict
        ),
        max_warming_K=args.max_warming_k,
        solve=replace(
            SolveOptions(),
            estimate_kinematics=not args.no_kinematics,
            estimate_stereo=not args.fixed_stereo,
            estimate_intrinsics=not args.fixed_intrinsics,
        ),
    )
    client = ControllerClient(args.port)
    camera = None
    try:
        connect_checked(client, args.port, cell.robot.model)
        camera = NetworkCamera(args.camera, stereo)
        done = run_calibration_tour(cell, tour, client, camera, options, _progress(args.quiet),
                                    source)  # fmt: skip
    finally:
        client.close()
        if camera is not None:
            camera.close()
    if args.quiet:  # the warnings were not shown as the tour went (cell.calibration...soft_views)
        for d in done.dropped:
            print(d.warning(source, len(done.observations.views)), file=sys.stderr)
    if done.warming is not None:
        print(done.warming.line())
    print_result(done.result)
    cap = done.captures
    print(f"robot time {cap.robot_time_s:.1f} s on the controller clock (planned "
          f"{tour.tour.cycle_time_s:.1f} s); capture {cap.wall_s['capture_s']:.1f} s, detection "
          f"{cap.wall_s['detect_s']:.1f} s, solve {done.result.timings['total_s']:.2f} s; "
          f"total {done.wall_s:.1f} s")  # fmt: skip
    save_calibration(done.calibration, out)
    print(f"wrote {out}")
    return 0
