"""``holecell calibrate hand-eye``: the cell calibration offline, from recorded images and poses."""

from __future__ import annotations

import argparse
import sys

import numpy as np

from cell.commands.argtypes import output_file
from cell.commands.calibrate_stereo_cmd import add_board_arguments

DESCRIPTION = (
    "Estimates the hand-eye (the left camera's pose in tool0, T_tool0_camera), the target's "
    "pose in the robot base, the stereo head's extrinsics and, given joints and --cell, the "
    "identifiable D-H errors of the arm, in one least-squares adjustment of the reprojection "
    "errors of every view (both cameras), started from OpenCV's hand-eye. --poses CSV: one "
    "row per view with 'image' (or 'left_image,right_image' for pairs, names in --images DIR) "
    "and either q1_rad..q6_rad (needs --cell) or the flange pose in the base "
    "x_m,y_m,z_m,qx,qy,qz,qw. Prints every estimate with its standard deviation, the D-H terms "
    "the data cannot determine and why, the residuals per view and OpenCV's answers on the "
    "same views; writes cellcal.json (docs/calibration.md) only when the calibration "
    "succeeds. Refuses (exit 2, nothing written) bad CSVs (missing columns, degrees or "
    "millimetres, rows without an image), images without the target and pose sets that "
    "cannot determine the hand-eye (too few views, rotations about parallel axes)."
)


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``calibrate hand-eye`` to the ``calibrate`` subcommands."""
    p = sub.add_parser(
        "hand-eye",
        help="hand-eye, target pose, D-H errors and stereo extrinsics from recorded views",
        description=DESCRIPTION,
    )
    p.add_argument("--images", required=True, metavar="DIR", help="folder of the images")
    p.add_argument("--poses", required=True, metavar="CSV", help="one row per view (see above)")
    cams = p.add_mutually_exclusive_group(required=True)
    cams.add_argument("--stereo", metavar="JSON", help="stereo.json (stereo pairs)")
    cams.add_argument(
        "--intrinsics",
        metavar="FILE",
        help="mono camera: OpenCV FileStorage YAML/XML with camera_matrix, distortion_coefficients",
    )
    p.add_argument("--cell", metavar="CELL", help="cell file: the arm's kinematics (joints rows)")
    add_board_arguments(p)
    p.add_argument(
        "-o",
        "--output",
        type=output_file,
        default="cellcal.json",
        help="file to write (cellcal.json)",
    )
    p.add_argument(
        "--no-kinematics", action="store_true", help="do not estimate the D-H errors (joints rows)"
    )
    p.add_argument(
        "--max-edge-width",
        type=float,
        default=4.0,
        metavar="PX",
        help="widest edge (10-90 %% rise, px) of an image accepted as sharp (4)",
    )
    p.add_argument(
        "--fixed-stereo",
        action="store_true",
        help="take the stereo extrinsics from stereo.json as exact instead of estimating them",
    )
    p.add_argument(
        "--strict",
        action="store_true",
        help="refuse the whole set when one image fails a quality check (default: drop that "
        "view with a warning and go on if the rest still determines the calibration)",
    )
    p.set_defaults(handler=run)


def _check_limits(rows, arm, src: str) -> None:
    from cell.calibration.errors import CalibrationDataError

    for r in rows:
        bad = np.flatnonzero((r.q_rad < arm.lower - 1e-6) | (r.q_rad > arm.upper + 1e-6))
        if len(bad):
            j = int(bad[0])
            raise CalibrationDataError(
                src,
                f"q{j + 1}_rad = {r.q_rad[j]:g} is outside the joint limits of the cell's arm "
                f"[{arm.lower[j]:.4g}, {arm.upper[j]:.4g}] rad",
                r.row,
            )


def run(args: argparse.Namespace) -> int:
    """Handler: read, detect, solve, report, write."""
    from pathlib import Path

    from cell.calibration.errors import CalibrationDataError
    from cell.calibration.estimate import Cameras, SolveOptions, solve_calibration
    from cell.calibration.estimate.soft_views import solve_without
    from cell.calibration.file import cell_provenance, save_calibration
    from cell.calibration.inputs import observations_from_images, read_intrinsics, read_pose_csv
    from cell.commands.calibrate_report import print_result
    from cell.config import load_cell
    from measure.calibration import StereoCalibration
    from measure.target import TargetSpec

    try:
        spec = TargetSpec(args.pattern, args.cols, args.rows, args.pitch)
    except ValueError as exc:
        raise CalibrationDataError("--cols/--rows/--pitch", str(exc)) from None
    if spec.pitch_m > 0.2:
        raise CalibrationDataError("--pitch", f"{spec.pitch_m:g} m looks like millimetres")
    cell = load_cell(args.cell) if args.cell else None
    arm = cell.build_robot() if cell is not None else None
    dh = arm.dh if arm is not None else None
    rows = read_pose_csv(args.poses, use_joints=cell is not None)
    if arm is not None:
        _check_limits(rows, arm, args.poses)
    if args.stereo:
        st = StereoCalibration.load(args.stereo)
        cameras, content = Cameras.from_stereo(st), st.to_dict()
    else:
        first = Path(args.images) / (rows[0].image or rows[0].left_image or "")
        import cv2

        img = cv2.imread(str(first), cv2.IMREAD_UNCHANGED)
        size = (img.shape[1], img.shape[0]) if img is not None else None
        left = read_intrinsics(args.intrinsics, size)
        cameras = Cameras(left=left, source=args.intrinsics)
        content = {"K": left.K.tolist(), "dist": left.dist.tolist(), "size": list(left.image_size)}
    if not 0 < args.max_edge_width <= 50:
        raise CalibrationDataError(
            "--max-edge-width", f"{args.max_edge_width:g} px is not in (0, 50]"
        )
    dropped: list = []
    obs = observations_from_images(
        rows, args.images, spec, cameras, args.poses, args.max_edge_width, args.strict, dropped
    )
    for d in dropped:  # views left out for their quality (cell.calibration.estimate.soft_views)
        print(d.warning(str(args.poses), len(obs.views)), file=sys.stderr, flush=True)
    opts = SolveOptions(
        estimate_kinematics=not args.no_kinematics, estimate_stereo=not args.fixed_stereo
    )
    prov = cell_provenance(cell, dh, args.stereo or args.intrinsics, content)
    result = solve_without(dropped, str(args.poses), solve_calibration, obs, dh, opts, prov)
    print_result(result)
    save_calibration(result.calibration, args.output)
    print(f"wrote {args.output}")
    return 0
