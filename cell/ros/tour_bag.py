"""A tour as a ROS 2 bag (MCAP storage): what RViz and Foxglove replay.

Topics (times from the bag's start, ``start_ns``; docs/ros.md):

- ``/joint_trajectory`` (``trajectory_msgs/JointTrajectory``): the whole tour, every row of
  ``tour.json`` at ``k dt``;
- ``/display_planned_path`` (``moveit_msgs/DisplayTrajectory``): the same for RViz's MoveIt
  trajectory display, starting at home;
- ``/joint_states`` (``sensor_msgs/JointState``): the arm sampled at 100 Hz (linear between
  rows);
- ``/inspection/stops`` (``visualization_msgs/MarkerArray``): per stop, the view arrow and the
  hole id;
- ``/tf_static`` (``tf2_msgs/TFMessage``): cell -> the URDF's root link (when the cell is
  given).

Joint names are the tour's, which the planner took from the URDF.
"""

from __future__ import annotations

import shutil
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
from rosbags.rosbag2 import StoragePlugin, Writer

from cell.ros.errors import BagError
from cell.ros.markers import base_transform, stop_markers
from cell.ros.msgs import DISPLAY_TRAJECTORY, JOINT_STATE, JOINT_TRAJECTORY, MARKER_ARRAY, typestore
from cell.ros.samples import joint_states, joint_trajectory, make
from planner.tour import Tour

JOINT_STATE_HZ = 100.0
TOPICS = {
    "trajectory": "/joint_trajectory",
    "display": "/display_planned_path",
    "joint_states": "/joint_states",
    "stops": "/inspection/stops",
    "tf": "/tf_static",
}


def open_writer(out: str | Path, overwrite: bool) -> Writer:
    """A bag writer for folder ``out`` (refused when it exists, unless ``overwrite``)."""
    p = Path(out)
    if p.exists():
        if not overwrite:
            raise BagError(p, "exists already (give --overwrite, or another -o)")
        if not (p / "metadata.yaml").is_file():
            raise BagError(p, "exists and is not a bag folder: not overwritten")
        shutil.rmtree(p)
    return Writer(p, version=9, storage_plugin=StoragePlugin.MCAP)


def display_trajectory(store: Any, tour: Tour, traj_msg: Any) -> Any:
    """``DisplayTrajectory``: the tour's trajectory, starting from its home joint state."""
    start = make(
        store,
        "moveit_msgs/msg/RobotState",
        joint_state=make(
            store, JOINT_STATE, name=list(tour.joint_names), position=np.array(tour.home_q)
        ),
    )
    robot_traj = make(store, "moveit_msgs/msg/RobotTrajectory", joint_trajectory=traj_msg)
    return make(
        store,
        DISPLAY_TRAJECTORY,
        model_id=tour.robot_model,
        trajectory=[robot_traj],
        trajectory_start=start,
    )


def write_tour_bag(
    tour: Tour,
    out: str | Path,
    *,
    standoff_m: float = 0.25,
    T_cell_base: np.ndarray | None = None,
    base_link: str = "base_link",
    start_ns: int = 0,
    overwrite: bool = False,
    extra: Sequence[tuple[str, str, list[tuple[int, Any]]]] = (),
) -> dict[str, int]:
    """Write ``tour`` as a bag in folder ``out``, and the ``extra`` topics (topic, type,
    [(time ns, message)]); the number of messages per topic."""
    store = typestore()
    q = np.asarray(tour.trajectory, dtype=np.float64)
    if q.ndim != 2 or len(q) == 0:
        raise BagError(out, "the tour has no trajectory to write")
    names = list(tour.joint_names)
    counts: dict[str, int] = {}
    with open_writer(out, overwrite) as w:
        conns = {
            "trajectory": w.add_connection(TOPICS["trajectory"], JOINT_TRAJECTORY, typestore=store),
            "display": w.add_connection(TOPICS["display"], DISPLAY_TRAJECTORY, typestore=store),
            "joint_states": w.add_connection(TOPICS["joint_states"], JOINT_STATE, typestore=store),
            "stops": w.add_connection(TOPICS["stops"], MARKER_ARRAY, typestore=store),
        }

        def put(key: str, t_ns: int, msg: Any, msgtype: str) -> None:
            w.write(conns[key], t_ns, store.serialize_cdr(msg, msgtype))
            counts[TOPICS[key]] = counts.get(TOPICS[key], 0) + 1

        if T_cell_base is not None:
            conns["tf"] = w.add_connection(TOPICS["tf"], "tf2_msgs/msg/TFMessage", typestore=store)
            put("tf", start_ns, base_transform(store, T_cell_base, base_link, start_ns),
                "tf2_msgs/msg/TFMessage")  # fmt: skip
        traj = joint_trajectory(store, names, q, tour.dt, start_ns, "")
        put("trajectory", start_ns, traj, JOINT_TRAJECTORY)
        put("display", start_ns, display_trajectory(store, tour, traj), DISPLAY_TRAJECTORY)
        put("stops", start_ns, stop_markers(store, tour.stops, standoff_m, start_ns), MARKER_ARRAY)
        for t_ns, msg in joint_states(store, names, q, tour.dt, JOINT_STATE_HZ, start_ns):
            put("joint_states", t_ns, msg, JOINT_STATE)
        for topic, msgtype, messages in extra:
            conn = w.add_connection(topic, msgtype, typestore=store)
            for t_ns, msg in messages:
                w.write(conn, t_ns, store.serialize_cdr(msg, msgtype))
            counts[topic] = len(messages)
    return counts
