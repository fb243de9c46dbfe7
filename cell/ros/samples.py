"""Messages from a tour: any ROS 2 message built with its unset fields zero (``make``), the
trajectory as ``JointTrajectory``, the arm's state at 100 Hz as ``JointState`` samples, and
the stops as markers. Times in integer nanoseconds from the tour's start."""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray
from rosbags.typesys.store import Typestore

from cell.ros.msgs import JOINT_STATE, JOINT_TRAJECTORY

_NUMPY = {
    "bool": np.bool_, "byte": np.uint8, "char": np.uint8, "int8": np.int8, "uint8": np.uint8,
    "int16": np.int16, "uint16": np.uint16, "int32": np.int32, "uint32": np.uint32,
    "int64": np.int64, "uint64": np.uint64, "float32": np.float32, "float64": np.float64,
}  # fmt: skip


def make(store: Typestore, msgtype: str, **fields: Any) -> Any:
    """A message of ``msgtype`` with ``fields`` set and every other field zero or empty."""
    _, defs = store.fielddefs[msgtype]
    values = {}
    for name, (kind, spec) in defs:
        if name in fields:
            values[name] = fields[name]
        else:
            values[name] = _zero(store, kind, spec)
    return store.types[msgtype](**values)


def _zero(store: Typestore, kind: Any, spec: Any) -> Any:
    k = int(kind)
    if k == 1:  # a base type
        base = spec[0]
        return "" if base == "string" else _NUMPY[base](0).item() if base != "bool" else False
    if k == 2:  # a message
        return make(store, spec)
    if k == 3:  # a fixed-size array
        (ekind, espec), size = spec
        if int(ekind) == 1 and espec[0] in _NUMPY:
            return np.zeros(size, dtype=_NUMPY[espec[0]])
        return [_zero(store, ekind, espec) for _ in range(size)]
    (ekind, espec), _ = spec  # a sequence
    if int(ekind) == 1 and espec[0] in _NUMPY:
        return np.zeros(0, dtype=_NUMPY[espec[0]])
    return []


def stamp(store: Typestore, t_ns: int, kind: str = "builtin_interfaces/msg/Time") -> Any:
    """A ``Time`` (or ``Duration``) of ``t_ns`` nanoseconds."""
    return store.types[kind](sec=int(t_ns // 1_000_000_000), nanosec=int(t_ns % 1_000_000_000))


def header(store: Typestore, t_ns: int, frame: str) -> Any:
    return store.types["std_msgs/msg/Header"](stamp=stamp(store, t_ns), frame_id=frame)


def joint_trajectory(
    store: Typestore, names: list[str], q: NDArray[np.float64], dt: float, start_ns: int, frame: str
) -> Any:
    """The whole trajectory, one point per row of ``q`` every ``dt`` s (positions only, rad)."""
    point = "trajectory_msgs/msg/JointTrajectoryPoint"
    points = [
        make(
            store,
            point,
            positions=np.asarray(row, dtype=np.float64),
            time_from_start=stamp(store, round(k * dt * 1e9), "builtin_interfaces/msg/Duration"),
        )
        for k, row in enumerate(q)
    ]
    return make(
        store,
        JOINT_TRAJECTORY,
        header=header(store, start_ns, frame),
        joint_names=list(names),
        points=points,
    )


def sample_at(q: NDArray[np.float64], dt: float, t: float) -> NDArray[np.float64]:
    """The trajectory's positions at ``t`` s: the row there, linear between rows (rad)."""
    x = min(max(t / dt, 0.0), len(q) - 1.0)
    k = int(np.floor(x))
    if k >= len(q) - 1 or abs(x - round(x)) < 1e-9:
        return np.array(q[min(round(x), len(q) - 1)], dtype=np.float64)
    w = x - k
    return (1.0 - w) * q[k] + w * q[k + 1]


def joint_states(
    store: Typestore,
    names: list[str],
    q: NDArray[np.float64],
    dt: float,
    rate_hz: float,
    start_ns: int,
) -> list[tuple[int, Any]]:
    """``JointState`` every 1/``rate_hz`` s over the trajectory, with their bag times (ns)."""
    duration = (len(q) - 1) * dt
    n = int(np.floor(duration * rate_hz + 1e-9)) + 1
    out = []
    for i in range(n):
        t_ns = start_ns + round(i * 1e9 / rate_hz)
        msg = make(
            store,
            JOINT_STATE,
            header=header(store, t_ns, ""),
            name=list(names),
            position=sample_at(q, dt, i / rate_hz),
        )
        out.append((t_ns, msg))
    return out
