"""Markers (``visualization_msgs/MarkerArray``) for the stops of a tour and the holes of a
run, in the cell frame (``cell``), and the static transform from it to the arm's base."""

from __future__ import annotations

from typing import Any

import numpy as np
from rosbags.typesys.store import Typestore
from scipy.spatial.transform import Rotation

from cell.ros.samples import header, make

ARROW, SPHERE, CYLINDER, TEXT = 0, 2, 3, 9
FRAME = "cell"


def _point(store: Typestore, p: Any) -> Any:
    return store.types["geometry_msgs/msg/Point"](x=float(p[0]), y=float(p[1]), z=float(p[2]))


def _pose(store: Typestore, xyz: Any, quat_xyzw: Any = (0.0, 0.0, 0.0, 1.0)) -> Any:
    q = store.types["geometry_msgs/msg/Quaternion"](
        x=float(quat_xyzw[0]), y=float(quat_xyzw[1]), z=float(quat_xyzw[2]), w=float(quat_xyzw[3])
    )
    return store.types["geometry_msgs/msg/Pose"](position=_point(store, xyz), orientation=q)


def _color(store: Typestore, rgba: tuple[float, float, float, float]) -> Any:
    r, g, b, a = rgba
    return store.types["std_msgs/msg/ColorRGBA"](r=r, g=g, b=b, a=a)


def _vec3(store: Typestore, x: float, y: float, z: float) -> Any:
    return store.types["geometry_msgs/msg/Vector3"](x=x, y=y, z=z)


def marker(store: Typestore, t_ns: int, ns: str, mid: int, kind: int, **fields: Any) -> Any:
    """One marker in the cell frame, added (action 0)."""
    return make(
        store,
        "visualization_msgs/msg/Marker",
        header=header(store, t_ns, FRAME),
        ns=ns,
        id=mid,
        type=kind,
        action=0,
        **fields,
    )


def stop_markers(store: Typestore, stops: list[Any], standoff_m: float, t_ns: int) -> Any:
    """Per stop: an arrow along the camera's view (TCP z, ``standoff_m`` long) and its hole id."""
    items = []
    for k, s in enumerate(stops):
        xyz = np.array(s.tcp_pose["xyz"], dtype=float)
        z = Rotation.from_quat(s.tcp_pose["quat_xyzw"]).as_matrix()[:, 2]
        items.append(
            marker(
                store, t_ns, "stops", 2 * k, ARROW,
                pose=_pose(store, (0, 0, 0)),
                points=[_point(store, xyz), _point(store, xyz + standoff_m * z)],
                scale=_vec3(store, 0.005, 0.012, 0.02),
                color=_color(store, (0.1, 0.5, 1.0, 0.9)),
            )
        )  # fmt: skip
        items.append(
            marker(
                store, t_ns, "stops", 2 * k + 1, TEXT,
                pose=_pose(store, xyz + np.array([0.0, 0.0, 0.03])),
                scale=_vec3(store, 0.0, 0.0, 0.02),
                color=_color(store, (1.0, 1.0, 1.0, 1.0)),
                text=f"{k + 1}: {s.hole_id}",
            )
        )  # fmt: skip
    return store.types["visualization_msgs/msg/MarkerArray"](markers=items)


def hole_markers(store: Typestore, holes: list[dict[str, Any]], t_ns: int) -> Any:
    """Per measured hole (cell frame, m): a thin disc of its measured diameter on its axis,
    green when it passed, red when not, grey undecided; its id and deviation as text."""
    items = []
    for k, h in enumerate(holes):
        n = np.asarray(h["normal"], dtype=float)
        quat = Rotation.align_vectors([n], [[0.0, 0.0, 1.0]])[0].as_quat()
        rgba = {True: (0.1, 0.8, 0.2, 0.9), False: (0.9, 0.1, 0.1, 0.9)}.get(
            h.get("passed"), (0.6, 0.6, 0.6, 0.9)
        )
        d = float(h["diameter_m"])
        items.append(
            marker(
                store, t_ns, "holes", 2 * k, CYLINDER,
                pose=_pose(store, h["center_m"], quat),
                scale=_vec3(store, d, d, 0.001),
                color=_color(store, rgba),
            )
        )  # fmt: skip
        items.append(
            marker(
                store, t_ns, "holes", 2 * k + 1, TEXT,
                pose=_pose(store, np.asarray(h["center_m"]) + 0.02 * n),
                scale=_vec3(store, 0.0, 0.0, 0.015),
                color=_color(store, (1.0, 1.0, 1.0, 1.0)),
                text=h["label"],
            )
        )  # fmt: skip
    return store.types["visualization_msgs/msg/MarkerArray"](markers=items)


def base_transform(store: Typestore, T_cell_base: np.ndarray, base_link: str, t_ns: int) -> Any:
    """``tf2_msgs/TFMessage`` with the static transform cell -> the URDF's root link."""
    q = Rotation.from_matrix(T_cell_base[:3, :3]).as_quat()
    tr = store.types["geometry_msgs/msg/Transform"](
        translation=_vec3(store, *(float(v) for v in T_cell_base[:3, 3])),
        rotation=store.types["geometry_msgs/msg/Quaternion"](
            x=float(q[0]), y=float(q[1]), z=float(q[2]), w=float(q[3])
        ),
    )
    ts = store.types["geometry_msgs/msg/TransformStamped"](
        header=header(store, t_ns, FRAME), child_frame_id=base_link, transform=tr
    )
    return store.types["tf2_msgs/msg/TFMessage"](transforms=[ts])
