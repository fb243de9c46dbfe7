"""``holecell export ros2`` on a tour: time to write the bag, its size, and the trajectory read
back by two readers (mcap-ros2-support with the bag's own schemas, rosbags with its ROS 2
Humble types) against tour.json.

Usage: ``.venv/bin/python benchmarks/ros_export.py TOUR.json [--cell CELL.yaml]`` (plan the
built-in tour first: ``holecell plan motorcycle_frame -o tour.json``).
"""

from __future__ import annotations

import argparse
import json
import tempfile
import time
from pathlib import Path

import numpy as np
from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory
from rosbags.rosbag2 import Reader
from rosbags.typesys import Stores, get_typestore

from cell.config import load_cell
from cell.ros.tour_bag import write_tour_bag
from planner.tour import load_tour


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("tour")
    ap.add_argument("--cell", default=None)
    args = ap.parse_args()
    tour = load_tour(args.tour)
    rows = np.array(json.loads(Path(args.tour).read_text())["trajectory"])
    kwargs = {}
    if args.cell:
        cfg = load_cell(args.cell)
        kwargs = {"T_cell_base": cfg.T_cell_base(), "standoff_m": cfg.tool.standoff_m}
    with tempfile.TemporaryDirectory() as tmp:
        bag = Path(tmp) / "bag"
        t0 = time.perf_counter()
        counts = write_tour_bag(tour, bag, **kwargs)
        t_write = time.perf_counter() - t0
        size = sum(p.stat().st_size for p in bag.iterdir())
        t0 = time.perf_counter()
        with next(bag.glob("*.mcap")).open("rb") as fh:
            reader = make_reader(fh, decoder_factories=[DecoderFactory()])
            got = {
                ch.topic: dec
                for _, ch, _, dec in reader.iter_decoded_messages(topics=["/joint_trajectory",
                                                                          "/display_planned_path"])
            }  # fmt: skip
        t_mcap = time.perf_counter() - t0
        q_mcap = np.array([p.positions for p in got["/joint_trajectory"].points])
        q_disp = np.array(
            [
                p.positions
                for p in got["/display_planned_path"].trajectory[0].joint_trajectory.points
            ]
        )
        store = get_typestore(Stores.ROS2_HUMBLE)
        t0 = time.perf_counter()
        with Reader(bag) as r:
            conn = [c for c in r.connections if c.topic == "/joint_trajectory"]
            traj = next(store.deserialize_cdr(raw, c.msgtype) for c, _, raw in r.messages(conn))
        t_rosbags = time.perf_counter() - t0
        q_rosbags = np.array([p.positions for p in traj.points])
    print(f"tour: {len(tour.stops)} stops, {len(rows)} trajectory rows at dt {tour.dt} s, "
          f"cycle {tour.cycle_time_s:.2f} s")  # fmt: skip
    print("| write s | bag MB | messages | read mcap-ros2 s | read rosbags s | "
          "max |dq| mcap | max |dq| DisplayTrajectory | max |dq| rosbags |")  # fmt: skip
    print("|---:|---:|---|---:|---:|---:|---:|---:|")
    msgs = ", ".join(f"{k} {v}" for k, v in counts.items())
    print(
        f"| {t_write:.2f} | {size / 1e6:.2f} | {msgs} | {t_mcap:.2f} | {t_rosbags:.2f} | "
        f"{np.max(np.abs(q_mcap - rows)):.1e} | {np.max(np.abs(q_disp - rows)):.1e} | "
        f"{np.max(np.abs(q_rosbags - rows)):.1e} |"
    )


if __name__ == "__main__":
    main()
