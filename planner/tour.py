"""The planned inspection tour and its file, ``tour.json``.

The file holds what a runner needs and what lets it refuse a tour made for
another cell: the cell name and the SHA-256 of the cell file text, the robot
model and joint names, the ordered stops, the trajectory sampled at the
controller period, and the holes left out with their reasons. SI units: m, rad, s.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from planner.errors import TourFileError
from robots.files import write_text_atomic

FORMAT = "holecell.tour"
FORMAT_VERSION = 1


@dataclass(frozen=True)
class Stop:
    """One inspection stop: the arm rests at ``q`` (rad) from ``t`` (s) for ``dwell_s``.

    ``tcp_pose`` is ``T_cell_tcp`` in file notation ``{xyz, quat_xyzw}`` (m).
    """

    hole_id: str
    q: tuple[float, ...]
    t: float
    dwell_s: float
    tcp_pose: dict[str, list[float]]
    branch: int


@dataclass(frozen=True)
class LeftOut:
    """A hole that is not in the tour and why (``"out of reach"``, ``"in collision ..."``)."""

    hole_id: str
    reason: str


@dataclass
class Tour:
    """A timed inspection tour from home through every reachable hole back to home.

    ``status`` is ``"complete"`` when every hole is visited, ``"partial"`` when some
    were left out. ``trajectory`` has one row of joint positions (rad) every ``dt`` s,
    from t = 0 to ``cycle_time_s``. ``timings_s`` holds planning time per stage.
    """

    cell_name: str
    cell_sha256: str
    robot_model: str
    joint_names: tuple[str, ...]
    home_q: tuple[float, ...]
    stops: list[Stop]
    left_out: list[LeftOut]
    dt: float
    trajectory: NDArray[np.float64]
    cycle_time_s: float
    planning_time_s: float
    timings_s: dict[str, float] = field(default_factory=dict)
    settings: dict[str, Any] = field(default_factory=dict)

    @property
    def status(self) -> str:
        """``"complete"`` or ``"partial"``."""
        return "partial" if self.left_out else "complete"

    @property
    def hole_order(self) -> list[str]:
        """Hole ids in visiting order."""
        return [s.hole_id for s in self.stops]

    def to_dict(self) -> dict[str, Any]:
        """The JSON-ready mapping written to ``tour.json``."""
        return {
            "format": FORMAT,
            "version": FORMAT_VERSION,
            "status": self.status,
            "cell": {"name": self.cell_name, "sha256": self.cell_sha256},
            "robot": {"model": self.robot_model, "joint_names": list(self.joint_names)},
            "home_q": [float(v) for v in self.home_q],
            "stops": [
                {
                    "hole_id": s.hole_id,
                    "q": [float(v) for v in s.q],
                    "t": s.t,
                    "dwell_s": s.dwell_s,
                    "tcp_pose": s.tcp_pose,
                    "branch": s.branch,
                }
                for s in self.stops
            ],
            "left_out": [{"hole_id": h.hole_id, "reason": h.reason} for h in self.left_out],
            "cycle_time_s": self.cycle_time_s,
            "planning_time_s": self.planning_time_s,
            "timings_s": dict(self.timings_s),
            "settings": dict(self.settings),
            "dt": self.dt,
            "trajectory": [[float(v) for v in row] for row in self.trajectory],
        }

    def save(self, path: str | Path) -> Path:
        """Write ``tour.json`` (via a temporary file, so an existing file is never half-written)."""
        return write_json(path, self.to_dict())


def pose_dict(T: NDArray[np.float64]) -> dict[str, list[float]]:
    """A 4×4 transform as ``{xyz, quat_xyzw}`` (m)."""
    T = np.asarray(T, dtype=float)
    return {
        "xyz": [float(v) for v in T[:3, 3]],
        "quat_xyzw": [float(v) for v in Rotation.from_matrix(T[:3, :3]).as_quat()],
    }


def write_json(path: str | Path, data: dict[str, Any]) -> Path:
    """Write ``data`` as JSON to ``path`` via a temporary name beside it (an existing file is
    never half-written); returns the path."""
    return write_text_atomic(path, json.dumps(data, indent=1))


def read_json_object(path: str | Path) -> dict[str, Any]:
    """The JSON object in file ``path``; a missing or unreadable file, or one that holds no
    JSON object, raises :class:`TourFileError` naming the file."""
    p = Path(path)
    try:
        data = json.loads(p.read_text())
    except FileNotFoundError as exc:
        raise TourFileError(str(p), "file", "not found") from exc
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise TourFileError(str(p), "file", f"not readable as JSON ({exc})") from exc
    if not isinstance(data, dict):
        raise TourFileError(str(p), "file", "expected a JSON object")
    return data


def _require(data: dict[str, Any], key: str, kind: type | tuple[type, ...], where: str) -> Any:
    if key not in data:
        raise TourFileError(where, key, "missing")
    value = data[key]
    if not isinstance(value, kind):
        raise TourFileError(where, key, f"expected {kind}, got {type(value).__name__}")
    return value


def _vector(value: Any, n: int, where: str, name: str) -> tuple[float, ...]:
    arr = np.asarray(value, dtype=float) if isinstance(value, list) else None
    if arr is None or arr.shape != (n,) or not np.all(np.isfinite(arr)):
        raise TourFileError(where, name, f"expected {n} finite numbers, got {value!r}")
    return tuple(float(v) for v in arr)


def tour_from_dict(data: dict[str, Any], where: str = "<tour>") -> Tour:
    """Rebuild a :class:`Tour` from its mapping; errors name ``where`` and the field."""
    if data.get("format") != FORMAT:
        raise TourFileError(where, "format", f"expected {FORMAT!r}, got {data.get('format')!r}")
    if data.get("version") != FORMAT_VERSION:
        raise TourFileError(where, "version", f"unsupported version {data.get('version')!r}")
    cell = _require(data, "cell", dict, where)
    robot = _require(data, "robot", dict, where)
    names = tuple(_require(robot, "joint_names", list, where))
    n = len(names)
    stops = []
    for i, s in enumerate(_require(data, "stops", list, where)):
        at = f"stops[{i}]"
        if not isinstance(s, dict):
            raise TourFileError(where, at, "expected a mapping")
        stops.append(
            Stop(
                hole_id=str(_require(s, "hole_id", str, where)),
                q=_vector(s.get("q"), n, where, f"{at}.q"),
                t=float(_require(s, "t", (int, float), where)),
                dwell_s=float(_require(s, "dwell_s", (int, float), where)),
                tcp_pose=_require(s, "tcp_pose", dict, where),
                branch=int(_require(s, "branch", int, where)),
            )
        )
    rows = _require(data, "trajectory", list, where)
    traj = np.asarray(rows, dtype=float) if rows else np.zeros((0, n))
    if traj.ndim != 2 or traj.shape[1] != n or not np.all(np.isfinite(traj)):
        raise TourFileError(where, "trajectory", f"expected rows of {n} finite numbers")
    dt = float(_require(data, "dt", (int, float), where))
    if not (dt > 0 and math.isfinite(dt)):
        raise TourFileError(where, "dt", f"must be a positive number of seconds, got {dt!r}")
    left = []
    for i, h in enumerate(_require(data, "left_out", list, where)):
        if not isinstance(h, dict):
            raise TourFileError(where, f"left_out[{i}]", "expected a mapping")
        hole_id = _require(h, "hole_id", str, where)
        left.append(LeftOut(str(hole_id), str(_require(h, "reason", str, where))))
    return Tour(
        cell_name=str(_require(cell, "name", str, where)),
        cell_sha256=str(_require(cell, "sha256", str, where)),
        robot_model=str(_require(robot, "model", str, where)),
        joint_names=names,
        home_q=_vector(data.get("home_q"), n, where, "home_q"),
        stops=stops,
        left_out=left,
        dt=dt,
        trajectory=traj,
        cycle_time_s=float(_require(data, "cycle_time_s", (int, float), where)),
        planning_time_s=float(_require(data, "planning_time_s", (int, float), where)),
        timings_s=dict(data.get("timings_s", {})),
        settings=dict(data.get("settings", {})),
    )


def load_tour(path: str | Path) -> Tour:
    """Read ``tour.json``; a missing, unreadable or malformed file raises :class:`TourFileError`."""
    return tour_from_dict(read_json_object(path), str(Path(path)))
