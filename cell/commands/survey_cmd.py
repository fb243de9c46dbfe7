"""``holecell survey``: run the survey tour, adjust the marker network, write ``markers.json``."""

from __future__ import annotations

import argparse
from pathlib import Path

DESCRIPTION = (
    "Surveys the cell's reference markers (docs/referencing.md): plans the survey tour (views "
    "converging on every hole group's markers at two distances, the table's markers, overview "
    "views; each view turned about its axis until the arm reaches it; of those, the fewest "
    "that see every marker in 6 stereo views from rays 35 deg apart), runs it on the "
    "controller at --port, detects and identifies the markers in both images of the head at "
    "--camera, and solves one bundle adjustment (GTSAM) of the markers, every view's pose, the "
    "head self-calibrated and the scale bars. Writes OUT (markers.json: positions, covariance, "
    "gauge, the self-calibrated head, provenance) only when the survey holds. Refuses (exit 2, "
    "one line, nothing written) a marker in fewer than 3 views, rays meeting at less than 20 "
    "deg, and a network in pieces; an observation over 5 sigma is named and dropped."
)


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``survey`` to the top-level commands."""
    from cell.commands.argtypes import non_negative_float, output_file, positive_float
    from cell.referencing.sigma import SIGMA_FLOOR_PX

    p = sub.add_parser("survey", help="survey the reference markers: markers.json",
                       description=DESCRIPTION)  # fmt: skip
    p.add_argument("cell", nargs="?", default=None, help="cell file (default: built-in)")
    p.add_argument("--port", required=True, help="controller port URL")
    p.add_argument(
        "--camera", required=True, help="stereo head: tcp://HOST:PORT or gige://IP_LEFT,IP_RIGHT"
    )
    p.add_argument(
        "-o",
        "--output",
        type=output_file,
        default="markers.json",
        help="file to write (markers.json)",
    )
    p.add_argument(
        "--settle-s",
        type=non_negative_float,
        default=0.2,
        help="wait after 'in position' before each capture, s (%(default)s)",
    )
    p.add_argument(
        "--sigma-px",
        type=positive_float,
        default=0.05,
        help="the markers' stated centre noise per image axis, px (%(default)s): the first "
        "adjustments' weights and the outlier limit",
    )
    p.add_argument(
        "--sigma-floor-px",
        type=non_negative_float,
        default=SIGMA_FLOOR_PX,
        help="the smallest centre noise the final adjustment weighs with and states the "
        "covariances at, px (%(default)s: the best published target-centre accuracy)",
    )
    p.add_argument("--seed", type=int, default=0, help="seed of the tour's planning")
    p.add_argument("--quiet", action="store_true", help="no progress lines")
    p.set_defaults(handler=run)


def _progress(quiet: bool):
    def show(event: str, data: dict) -> None:
        if event == "view" and (data["k"] % 20 == 0 or data["k"] == data["n"]):
            print(f"  view {data['k']}/{data['n']} {data['id']}: {data['markers']} markers",
                  flush=True)  # fmt: skip

    return None if quiet else show


def run(args: argparse.Namespace) -> int:
    """Handler: plan the survey tour, connect, run, adjust, report, write."""
    from cell.camera import cell_stereo
    from cell.camera.open import check_camera_url, open_camera
    from cell.commands.survey_report import print_survey
    from cell.config import load_cell
    from cell.errors import CellError
    from cell.referencing import save_markers
    from cell.referencing.survey.run import SurveyRunOptions, run_survey
    from cell.referencing.survey.tour import plan_survey_tour
    from planner import Options

    out = Path(args.output)
    check_camera_url(args.camera)
    cell = load_cell(args.cell)
    if not cell.reference_markers:
        raise CellError(f"cell {cell.name!r}: reference_markers: the cell has none to survey")
    stereo = cell_stereo(cell)
    print("planning the survey tour ...", flush=True)
    planned = plan_survey_tour(cell, stereo, options=Options(seed=args.seed))
    print(
        f"  {len(planned.tour.stops)} views, {planned.tour.cycle_time_s:.0f} s of robot time; "
        f"{len(planned.left_out)} planned views out of reach or in collision",
        flush=True,
    )
    from cell.commands.controller_check import connect_checked
    from cell.link.client import ControllerClient

    client = ControllerClient(args.port)
    camera = None
    try:
        connect_checked(client, args.port, cell.robot.model)
        camera = open_camera(args.camera, stereo)
        done = run_survey(cell, planned, client, camera, stereo,
                          SurveyRunOptions(args.settle_s, args.sigma_px, args.sigma_floor_px),
                          _progress(args.quiet))  # fmt: skip
    finally:
        client.close()
        if camera is not None:
            camera.close()
    print_survey(done)
    save_markers(out, done.result, cell, stereo)
    print(f"wrote {out}")
    return 0
