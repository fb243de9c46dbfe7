"""``holecell plan-calibration [CELL] -o caltour.json``: plan the calibration tour of a cell.

Chooses ``--views`` views of the cell's ``calibration_target`` by experimental design
(:mod:`cell.calibration.plan.plan`), orders and times them with the hole tour's machinery and
writes ``caltour.json`` (``planner.calibration.tour``); prints the robot time, the planning time,
the design's geometric figures and the predicted σ of the calibration parameters.
"""

from __future__ import annotations

import argparse
import gc
from pathlib import Path

import numpy as np

from cell.calibration.plan import CRITERIA, CalibrationPlanOptions, cell_target, plan_calibration
from cell.camera import cell_stereo
from cell.commands.argtypes import non_negative_float, positive_int
from cell.commands.plan_cmd import StageBars
from cell.config import CellConfig, load_cell
from cell.config.tours import check_tour, hole_stops
from cell.errors import CellError
from planner import Options, load_tour
from planner.calibration import CalibrationTour


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``plan-calibration`` subcommand."""
    d = CalibrationPlanOptions()
    p = sub.add_parser(
        "plan-calibration",
        help="plan the calibration tour (views of the calibration target) and write caltour.json",
        description=(
            "Reads CELL (default: the built-in cell) and writes OUT (caltour.json): views of the "
            "cell's calibration_target chosen by experimental design for the hand-eye, the target "
            "in the base, the arm's D-H errors and the stereo extrinsics (large rotations about "
            "axes far from parallel, the board over both whole images, the joints over the hole "
            "tour's range), ordered and timed like the hole tour (collision-free, jerk-limited), "
            "with each view's board pose in both cameras and the predicted parameter σ."
        ),
    )
    p.add_argument("cell", nargs="?", default=None, help="cell file (default: built-in)")
    p.add_argument("-o", "--output", default="caltour.json", help="file to write (%(default)s)")
    p.add_argument("--views", type=positive_int, default=d.views, help="views (%(default)s)")
    p.add_argument(
        "--criterion", choices=CRITERIA, default=d.criterion,
        help="design: 'tcp' minimises the predicted TCP position variance at the hole tour's "
        "stops (I-optimal), 'd' maximises the information's determinant, 'geometric' keeps "
        "the geometric pre-selection (default: %(default)s)",
    )  # fmt: skip
    p.add_argument(
        "--tour", type=Path, metavar="tour.json", default=None,
        help="the hole tour whose joint range the views should cover (default: each hole's "
        "viewpoint nearest home)",
    )  # fmt: skip
    p.add_argument("--seed", type=int, default=0, help="random seed of the tour (default: 0)")
    p.add_argument(
        "--dwell", type=non_negative_float, default=Options().dwell_s,
        help="rest at each view for settling and capture, s (default: %(default)s)",
    )  # fmt: skip
    p.add_argument("--quiet", action="store_true", help="no progress bars")
    p.set_defaults(handler=run_plan_calibration)


def _stops(cell: CellConfig, tour_path: Path | None) -> np.ndarray:
    if tour_path is None:
        return hole_stops(cell)[1]
    tour = load_tour(tour_path)
    check_tour(tour, cell, str(tour_path))
    if not tour.stops:
        raise CellError(f"{tour_path}: stops: the tour has no stops to take the joint range from")
    return np.array([s.q for s in tour.stops], dtype=float)


def summary(cal: CalibrationTour, path: Path) -> list[str]:
    """Human-readable summary lines of a planned calibration tour."""
    tour, d = cal.tour, cal.design
    lines = [
        f"cell          {tour.cell_name}  (sha256 {tour.cell_sha256[:12]}...)",
        f"views         {len(tour.stops)} of {d['candidates']} feasible ({d['criterion']} design)",
        f"robot time    {tour.cycle_time_s:.1f} s  (dwell {tour.settings.get('dwell_s', 0.0)} s "
        "per view)",
        f"planning time {tour.planning_time_s:.1f} s",
        f"geometry      rotation share {d['rotation_share']:.2f}, axis eigenvalue "
        f"{d['axis_eigen_min']:.2f}; image share {d['image_share']:.2f}; joint share "
        f"{d['joint_share']:.2f}",
        orientation_line(d, len(tour.stops)),
    ]
    lines += prediction_lines(cal.prediction)
    lines.append(f"written       {path}")
    return lines


def orientation_line(design: dict, views: int) -> str:
    """How many orientations the views hold and the smallest rotation between two of them
    (views from one direction at other distances or offsets share one: ``min_rotation_rad``,
    between any two views, is then 0 and says nothing about the hand-eye)."""
    k, gap = design["orientations"], design["min_rotation_between_orientations_rad"]
    shared = (
        "" if k == views else f" (the other {views - k} repeat one from another distance or offset)"
    )
    between = "" if gap is None else f", at least {np.degrees(gap):.1f} deg apart"
    return f"orientations  {k} distinct{between}{shared}"


def prediction_lines(p: dict) -> list[str]:
    """The predicted σ of ``calibration.prediction`` as summary lines (mm, deg, µm)."""
    if not p:
        return []
    return [
        f"predicted σ   hand-eye {p['hand_eye_sigma_m'] * 1e3:.4f} mm, "
        f"{np.degrees(p['hand_eye_sigma_rad']):.4f} deg; TCP {p['tcp_sigma_m'] * 1e6:.1f} um, "
        f"view point {p['view_point_sigma_m'] * 1e6:.1f} um RMS at the hole tour's "
        f"{p['stops']} stops",
        f"              {len(p['sigma'])} parameters estimated, {len(p['fixed'])} fixed "
        f"(condition {p['condition']:.0f}); corner noise {p['corner_sigma_px']:g} px, "
        f"repeatability {p['repeatability_sigma_m'] * 1e6:.1f} um per axis",
    ]


def run_plan_calibration(args: argparse.Namespace) -> int:
    """Plan and write the calibration tour; exit 0, or 2 on an error."""
    out = Path(args.output)
    if out.is_dir():
        raise CellError(f"-o {out}: is a directory; give a file name such as caltour.json")
    if not out.parent.exists():
        raise CellError(f"-o {out}: folder {out.parent} does not exist")
    cell = load_cell(args.cell)
    target = cell_target(cell)
    stops = _stops(cell, args.tour)
    options = CalibrationPlanOptions(
        views=args.views,
        criterion=args.criterion,
        tour=Options(seed=args.seed, dwell_s=args.dwell),
    )
    progress = None if args.quiet else StageBars()
    cal = plan_calibration(cell, target, cell_stereo(cell), stops, options, progress)
    gc.collect()  # free the OMPL objects now (their bindings complain if still alive at exit)
    cal.save(out)
    print("\n".join(summary(cal, out)))
    return 0
