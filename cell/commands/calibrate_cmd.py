"""``holecell calibrate``: stereo calibration from image pairs of a plate target."""

from __future__ import annotations

import argparse
import glob
from pathlib import Path

from cell.commands.measure_cmd import read_image
from measure.errors import CalibrationTargetError
from measure.stereo_calibrate import calibrate_stereo
from measure.target import TargetSpec


def _expand(items: list[str]) -> list[str]:
    out: list[str] = []
    for item in items:
        hits = sorted(glob.glob(item)) if any(c in item for c in "*?[") else [item]
        out.extend(hits)
    return out


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``calibrate`` subcommand."""
    p = sub.add_parser(
        "calibrate",
        help="stereo calibration from image pairs of a plate target",
        description=(
            "Reads pairs of left/right images of a chessboard or asymmetric circle grid "
            "(paired in sorted order), rejects unusable pairs with a reason, calibrates both "
            "cameras and their pose, prints the RMS and per-pair reprojection errors and "
            "writes stereo.json (only when the calibration succeeds)."
        ),
    )
    p.add_argument("--left", nargs="+", required=True, help="left images (files or a glob)")
    p.add_argument("--right", nargs="+", required=True, help="right images (files or a glob)")
    p.add_argument("--pattern", choices=("chessboard", "circles"), default="chessboard")
    p.add_argument("--cols", type=int, required=True, help="inner corners / circles per row")
    p.add_argument("--rows", type=int, required=True, help="inner corner / circle rows")
    p.add_argument("--pitch", type=float, required=True, help="square side / grid pitch (metres)")
    p.add_argument("-o", "--output", default="stereo.json", help="file to write (stereo.json)")
    p.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    """Handler: detect, calibrate, report, write."""
    lefts, rights = _expand(args.left), _expand(args.right)
    if not lefts or len(lefts) != len(rights):
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
    res = calibrate_stereo(pairs, spec)
    errors = dict(res.per_pair_px)
    reasons = dict(res.rejected)
    width = max(len(n) for n, _, _ in pairs)
    for name, _, _ in pairs:
        status = f"{errors[name]:.3f} px" if name in errors else f"rejected: {reasons[name]}"
        print(f"{name:<{width}}  {status}")
    st = res.stereo
    print(f"RMS reprojection error {res.rms_px:.3f} px over {len(errors)} pairs")
    f_l, f_r = st.K_left[0, 0], st.K_right[0, 0]
    print(f"baseline {st.baseline_m * 1e3:.3f} mm, f = {f_l:.1f} / {f_r:.1f} px")
    st.save(args.output)
    print(f"wrote {args.output}")
    return 0
