"""``holecell measure``: measure one hole from a stereo image pair."""

from __future__ import annotations

import argparse
import json

import numpy as np

from cell.commands.argtypes import hole_diameter_m, output_file
from measure import MeasureOptions, StereoCalibration, measure_hole
from measure.errors import ImageError, MeasurementError
from measure.image_input import read_image

__all__ = ["read_image", "register", "run"]


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``measure`` subcommand."""
    p = sub.add_parser(
        "measure",
        help="measure one hole from a stereo image pair (or many: --pairs)",
        description=(
            "Reads LEFT and RIGHT images (8- or 16-bit PNG/TIFF) and the stereo calibration "
            "(stereo.json); prints the hole's centre, axis and diameter in the left camera "
            "frame. Writes nothing. With --pairs DIR|LIST instead of LEFT RIGHT: every pair "
            "of a folder (left/ and right/ subfolders with the same file names, or names "
            "starting or ending with left/right: H01_left.png + H01_right.png, left01.jpg + "
            "right01.jpg, raw_left1.png + raw_right1.png) or of a list file (LEFT RIGHT [ID] "
            "per line, # comments) in one process, with a progress bar; a pair that fails is "
            "reported in its row (exit code 1) and the batch goes on; -o writes one row per "
            "pair (.csv or .json)."
        ),
    )
    p.add_argument("left", nargs="?", help="left camera image")
    p.add_argument("right", nargs="?", help="right camera image")
    p.add_argument("--pairs", metavar="DIR|LIST", help="measure every pair of a folder or list")
    p.add_argument(
        "-o",
        "--output",
        type=output_file,
        help="with --pairs: write the rows to FILE (.csv or .json)",
    )
    p.add_argument("--stereo", required=True, help="stereo calibration file (stereo.json)")
    p.add_argument(
        "--diameter", type=hole_diameter_m, default=None, help="expected diameter (metres)"
    )
    p.add_argument(
        "--method",
        choices=("default", "published"),
        default="default",
        help="edge/fit method: the default, or the published one (for comparison)",
    )
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.set_defaults(handler=run)


def _batch(args: argparse.Namespace) -> int:
    if args.pairs is None or args.left is not None:
        raise ImageError("pair", "--pairs DIR|LIST replaces LEFT RIGHT; -o needs --pairs")
    from cell.commands.measure_batch import run_batch

    return run_batch(args)


def _table(m) -> str:
    c = m.center_m * 1e3
    rows = [
        ("status", m.status),
        ("diameter", f"{m.diameter_m * 1e3:.4f} mm"),
        ("centre (left cam)", f"{c[0]:.4f}  {c[1]:.4f}  {c[2]:.4f} mm"),
        ("normal", "  ".join(f"{v:+.5f}" for v in m.normal)),
        ("rms residual", f"{m.rms_m * 1e3:.4f} mm ({m.rms_m * 1e6:.1f} µm)"),
        ("σ(radius)", f"{np.sqrt(m.cov_center_radius[3, 3]) * 1e3:.5f} mm"),
        ("points used/rejected/filled", f"{m.n_points} / {m.n_rejected} / {m.n_filled}"),
        ("time", f"{m.time_s * 1e3:.1f} ms"),
    ]
    if m.rim is not None:
        rows.insert(1, ("rim", m.rim.describe()))
    for k, reason in enumerate(m.suspect_reasons):
        rows.insert(1 + k, ("suspect because" if k == 0 else "", reason))
    width = max(len(k) for k, _ in rows)
    return "\n".join(f"{k:<{width}}  {v}" for k, v in rows)


def run(args: argparse.Namespace) -> int:
    """Handler: measure and print; with ``--json`` errors are JSON too (exit code 2)."""
    if args.pairs is not None or args.output is not None:
        return _batch(args)
    if args.left is None or args.right is None:
        raise ImageError("pair", "give LEFT and RIGHT images, or --pairs DIR|LIST")
    opts = MeasureOptions.published() if args.method == "published" else MeasureOptions()
    try:
        stereo = StereoCalibration.load(args.stereo)
        left = read_image(args.left, "left")
        right = read_image(args.right, "right")
        m = measure_hole(left, right, stereo, expected_diameter_m=args.diameter, options=opts)
    except MeasurementError as exc:
        if not args.json:
            raise
        print(json.dumps({"status": "error", "reason": str(exc)}))
        return 2
    if args.json:
        print(json.dumps(m.to_dict()))
    else:
        print(_table(m))
    return 0
