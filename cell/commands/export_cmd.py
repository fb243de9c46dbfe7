"""``holecell export ros2 tour.json|RUN_DIR -o BAG_DIR``: a tour or a run as a ROS 2 bag."""

from __future__ import annotations

import argparse
from pathlib import Path


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``export`` with its one format, ``ros2``."""
    p = sub.add_parser(
        "export",
        help="a tour or a run for other tools (ros2: a ROS 2 bag, MCAP storage)",
        description=(
            "ros2: writes a ROS 2 bag (MCAP storage) for RViz and Foxglove (docs/ros.md): "
            "the tour's whole trajectory as trajectory_msgs/JointTrajectory and "
            "moveit_msgs/DisplayTrajectory, /joint_states at 100 Hz, the stops as markers; "
            "for a run directory also the joint state at each capture and the measured holes."
        ),
    )
    p.add_argument("format", choices=("ros2",), help="the export format")
    p.add_argument("source", metavar="tour.json|RUN_DIR", help="a tour file or a run directory")
    p.add_argument("-o", "--output", default=None, help="bag folder (default: SOURCE_bag)")
    p.add_argument(
        "--cell", default=None, help="the tour's cell file (adds cell -> base /tf_static)"
    )
    p.add_argument("--overwrite", action="store_true", help="replace an existing bag folder")
    p.set_defaults(handler=run_export)


def run_export(args: argparse.Namespace) -> int:
    """Handler of ``holecell export``."""
    from cell.ros.run_bag import write_run_bag
    from cell.ros.tour_bag import write_tour_bag

    src = Path(args.source)
    out = Path(args.output) if args.output else src.with_name(src.stem + "_bag")
    if src.is_dir():
        counts = write_run_bag(src, out, overwrite=args.overwrite)
    else:
        from planner.tour import load_tour

        tour = load_tour(src)
        kwargs = {}
        if args.cell is not None:
            from cell.config import load_cell

            cfg = load_cell(args.cell)
            kwargs = {"T_cell_base": cfg.T_cell_base(), "standoff_m": cfg.tool.standoff_m}
        counts = write_tour_bag(tour, out, overwrite=args.overwrite, **kwargs)
    listed = ", ".join(f"{t} {n}" for t, n in counts.items())
    print(f"{out}: ROS 2 bag (MCAP) written: {listed}")
    return 0
