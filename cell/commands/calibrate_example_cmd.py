"""``holecell calibrate example DIR``: write a synthetic set to try ``calibrate hand-eye`` on."""

from __future__ import annotations

import argparse

from cell.commands.argtypes import positive_int

DESCRIPTION = (
    "Writes into DIR (new or empty) a synthetic hand-eye data set with a known truth: rendered "
    "images of an 8 x 6 chessboard of 12 mm (640 x 512 px; stereo pairs L00.png/R00.png, or "
    "view00.png with --mono), poses.csv (joints q1_rad..q6_rad of the built-in cell's arm, or "
    "flange poses with --flange), stereo.json (or intrinsics.yaml with --mono) and truth.json "
    "(what the calibration should find), then prints the 'holecell calibrate hand-eye' command "
    "that calibrates from it (docs/calibration.md, 'Try it')."
)


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``calibrate example`` to the ``calibrate`` subcommands."""
    p = sub.add_parser(
        "example",
        help="write a synthetic set of images and poses to try 'calibrate hand-eye' on",
        description=DESCRIPTION,
    )
    p.add_argument("folder", metavar="DIR", help="folder to write (new or empty)")
    p.add_argument("--views", type=positive_int, default=12, help="views (%(default)s)")
    p.add_argument("--seed", type=int, default=0, help="seed of the truth and views (0)")
    p.add_argument("--mono", action="store_true", help="one camera: images and intrinsics.yaml")
    p.add_argument(
        "--flange", action="store_true", help="flange poses instead of joints (no --cell)"
    )
    p.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    """Handler: write the set, print what was written and the command to run."""
    from cell.calibration.inputs import write_example_set

    s = write_example_set(
        args.folder, args.views, args.seed, stereo=not args.mono, joints=not args.flange
    )
    kind = "stereo pairs" if s.stereo else "mono images"
    poses = "joints" if s.joints else "flange poses"
    print(f"wrote {s.views} {kind}, {s.poses.name} ({poses}), {s.camera.name}, {s.truth.name}")
    print(f"  into {s.folder}")
    print("calibrate with:")
    print(f"  {s.command()}")
    return 0
