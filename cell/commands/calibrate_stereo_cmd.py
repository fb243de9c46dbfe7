"""``holecell calibrate stereo`` (and the older ``holecell calibrate --left ... --right ...``):
stereo calibration from image pairs of a plate target."""

from __future__ import annotations

import argparse
import glob
from pathlib import Path

import numpy as np

from cell.commands.argtypes import output_file
from cell.commands.measure_cmd import read_image
from measure.errors import CalibrationTargetError
from measure.stereo_calibrate import CalibrateOptions, calibrate_stereo
from measure.target import TargetSpec


def _expand(items: list[str]) -> list[str]:
    out: list[str] = []
    for item in items:
        hits = sorted(glob.glob(item)) if any(c in item for c in "*?[") else [item]
        out.extend(hits)
    return out


#: the stereo calibration's description (``calibrate stereo --help`` and ``calibrate --help``)
DESCRIPTION = (
    "Reads pairs of left/right images of a chessboard or asymmetric circle grid "
    "(paired in sorted order), rejects unusable pairs with a reason, calibrates both "
    "cameras and their pose, prints the RMS and per-pair reprojection errors and "
    "writes stereo.json with the parameters' standard deviations (only when the "
    "calibration succeeds). Refuses (exit 2, nothing written) a board with more "
    "corners than --cols/--rows, a square side that looks like millimetres and a "
    "baseline outside 10 mm - 2 m; names pairs whose error is above 3x the median."
)


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``calibrate stereo`` to the ``calibrate`` subcommands."""
    p = sub.add_parser(
        "stereo",
        help="stereo calibration from image pairs of a plate target",
        description=DESCRIPTION,
    )
    add_arguments(p, required=True)
    p.set_defaults(handler=run)


def add_arguments(p: argparse.ArgumentParser, required: bool) -> None:
    """The stereo calibration's options (``required=False`` for the old form's parent parser,
    whose handler checks them)."""
    p.add_argument("--left", nargs="+", required=required, help="left images (files or a glob)")
    p.add_argument("--right", nargs="+", required=required, help="right images (files or a glob)")
    add_board_arguments(p, required)
    p.add_argument(
        "-o",
        "--output",
        type=output_file,
        default="stereo.json",
        help="file to write (stereo.json)",
    )
    p.add_argument(
        "--drop-outliers",
        action="store_true",
        help="drop pairs above 3x the median reprojection error and calibrate again",
    )
    p.add_argument(
        "--bootstrap",
        type=int,
        default=100,
        metavar="N",
        help="resample the pairs N times for the standard deviations (0: Jacobian only)",
    )
    p.add_argument(
        "--force",
        action="store_true",
        help="write stereo.json even when a check refuses it (the problems are still printed)",
    )


def add_board_arguments(p: argparse.ArgumentParser, required: bool = True) -> None:
    """The board: ``--pattern``, ``--cols``, ``--rows``, ``--pitch`` (metres)."""
    p.add_argument("--pattern", choices=("chessboard", "circles"), default="chessboard")
    p.add_argument("--cols", type=int, required=required, help="inner corners / circles per row")
    p.add_argument("--rows", type=int, required=required, help="inner corner / circle rows")
    p.add_argument(
        "--pitch", type=float, required=required, help="square side / grid pitch (metres)"
    )


def run(args: argparse.Namespace) -> int:
    """Handler: detect, calibrate, report, write."""
    lefts, rights = _expand(args.left), _expand(args.right)
    for flag, given, found in (("--left", args.left, lefts), ("--right", args.right, rights)):
        if not found:
            raise CalibrationTargetError(f"{flag} {' '.join(given)}: no image matches", [])
    if len(lefts) != len(rights):
        raise CalibrationTargetError(
            f"need the same number of left and right images, got {len(lefts)} and {len(rights)}", []
        )
    try:
        spec = TargetSpec(args.pattern, args.cols, args.rows, args.pitch)
    except ValueError as exc:
        raise CalibrationTargetError(str(exc), []) from None
    pairs = []
    for lp, rp in zip(lefts, rights, strict=True):
        name = f"{Path(lp).name} / {Path(rp).name}"
        pairs.append((name, read_image(lp, "left"), read_image(rp, "right")))
    opts = CalibrateOptions(drop_outliers=args.drop_outliers, bootstrap=max(args.bootstrap, 0))
    res = calibrate_stereo(pairs, spec, opts)
    errors = dict(res.per_pair_px)
    reasons = dict(res.rejected)
    width = max(len(n) for n, _, _ in pairs)
    for name, _, _ in pairs:
        if name in errors:
            status = f"{errors[name]:.3f} px"
            retried = [
                f"{side}: {det}"
                for side, det in zip(("left", "right"), res.detectors[name], strict=True)
                if det != "fast" and spec.kind == "chessboard"
            ]
            if retried:
                status += f"  (detector {', '.join(retried)})"
        else:
            status = f"rejected: {reasons[name]}"
        print(f"{name:<{width}}  {status}")
    st = res.stereo
    u = st.uncertainty
    print(f"RMS reprojection error {res.rms_px:.3f} px over {len(errors)} pairs")
    f_l, f_r = st.K_left[0, 0], st.K_right[0, 0]
    if u is not None:
        b_std = float(np.sqrt(np.sum((st.T / st.baseline_m * u.T_std_m) ** 2)))
        print(
            f"baseline {st.baseline_m * 1e3:.3f} ± {b_std * 1e3:.3f} mm, "
            f"f = {f_l:.1f} ± {u.K_std_left_px[0]:.2f} / {f_r:.1f} ± {u.K_std_right_px[0]:.2f} px"
            f" (1 sigma, {u.method})"
        )
    for prob in res.problems:
        print(f"{'refused' if prob.refuse else 'warning'}: {prob.message}")
    if res.refused and not args.force:
        raise CalibrationTargetError(
            f"not written ({args.output}): "
            + "; ".join(p.kind.replace("_", " ") for p in res.refused)
            + " (see above; --force writes it anyway)",
            [],
        )
    st.save(args.output)
    print(f"wrote {args.output}")
    return 0
