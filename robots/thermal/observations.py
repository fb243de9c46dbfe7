"""Reference-target observations: what the stereo head saw, and what the model predicts it sees.

At fixed robot poses the stereo head measures fixed reference targets again and
again while the arm warms up. One observation row holds the time (s), the
target id, the joint vector (rad), the sensor readings (degC) and the measured
target position in the TCP frame (m). Rows with the same target and the same
joint vector form a *group*; the information is in how a group's measurements
move as the temperatures change.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robots.thermal.errors import ThermalDataError

Array = NDArray[np.float64]

#: joint vectors closer than this (rad) count as the same pose
SAME_POSE_TOL_RAD = 1e-6


@dataclass(frozen=True)
class CellGeometry:
    """The nominal cell around the arm.

    Attributes:
        T_cell_base: robot base pose in the cell frame (4x4).
        T_tool0_tcp: TCP (stereo head measuring point) relative to tool0 (4x4).
        targets_cell_m: reference target positions in the cell frame (m), by id.
    """

    T_cell_base: Array
    T_tool0_tcp: Array
    targets_cell_m: Mapping[str, Array]

    def targets_base_m(self, ids: list[str] | tuple[str, ...]) -> Array:
        """Nominal positions (N, 3) in the base frame of the targets ``ids``."""
        R, t = self.T_cell_base[:3, :3], self.T_cell_base[:3, 3]
        p_cell = np.array([self.targets_cell_m[i] for i in ids], dtype=float).reshape(-1, 3)
        return (p_cell - t) @ R


@dataclass(frozen=True)
class Observations:
    """A set of reference-target observations (row-aligned arrays)."""

    time_s: Array
    target_ids: tuple[str, ...]
    q_rad: Array
    temps_degC: Array  # noqa: N815 (unit suffix)
    sensor_names: tuple[str, ...]
    p_tcp_m: Array
    source: str = "observations"
    lines: tuple[int, ...] | None = None

    def __post_init__(self) -> None:
        n = len(self.time_s)
        shapes = {
            "target_ids": (len(self.target_ids),),
            "q_rad": np.shape(self.q_rad),
            "temps_degC": np.shape(self.temps_degC),
            "p_tcp_m": np.shape(self.p_tcp_m),
        }
        expected = {
            "target_ids": (n,),
            "q_rad": (n, 6),
            "temps_degC": (n, len(self.sensor_names)),
            "p_tcp_m": (n, 3),
        }
        for key, shape in shapes.items():
            if shape != expected[key]:
                raise ThermalDataError(
                    self.source, f"{key} has shape {shape}, expected {expected[key]}"
                )

    def __len__(self) -> int:
        return len(self.time_s)

    def groups(self) -> NDArray[np.int64]:
        """Group index (N,) int: rows with the same target id and the same joint vector.

        Joint vectors are compared after rounding to ``SAME_POSE_TOL_RAD``.
        """
        keys: dict[tuple[str, tuple[int, ...]], int] = {}
        out = np.empty(len(self), dtype=int)
        rounded = np.round(self.q_rad / SAME_POSE_TOL_RAD).astype(np.int64)
        for row, (tid, q) in enumerate(zip(self.target_ids, rounded, strict=True)):
            out[row] = keys.setdefault((tid, tuple(q.tolist())), len(keys))
        return out

    def check_targets(self, geometry: CellGeometry) -> None:
        """Raise :class:`ThermalDataError` naming the first row whose target id the cell lacks."""
        for row, tid in enumerate(self.target_ids):
            if tid not in geometry.targets_cell_m:
                known = ", ".join(sorted(geometry.targets_cell_m)) or "none"
                line = self.lines[row] if self.lines else None
                where = "" if line else f"observation {row + 1}: "
                raise ThermalDataError(
                    self.source,
                    f"{where}unknown target id {tid!r} (the cell's reference targets: {known})",
                    line=line,
                    column="target_id",
                )


def predict_p_tcp(T_base_tool0: Array, T_tool0_tcp: Array, p_base_m: Array) -> Array:
    """Target positions (N, 3) in the TCP frame from ``T_base_tool0`` (N, 4, 4), base positions."""
    T_base_tcp = T_base_tool0 @ T_tool0_tcp
    R = T_base_tcp[..., :3, :3]
    t = T_base_tcp[..., :3, 3]
    return np.einsum("nji,nj->ni", R, p_base_m - t)


def simulate_observations(
    T_base_tool0_at: Callable[[Array, Array], Array],
    sensor_readings_at: Callable[[Array], Array],
    sensor_names: tuple[str, ...],
    geometry: CellGeometry,
    plan: list[tuple[str, ArrayLike]],
    times_s: ArrayLike,
    noise_m: float = 0.0,
    seed: int = 0,
) -> Observations:
    """Observations of a true arm: every (target id, joint vector) of ``plan`` at every time.

    ``T_base_tool0_at(q (N,6), t (N,))`` is the true kinematics and
    ``sensor_readings_at(t (N,))`` the reported temperatures (e.g. the methods of
    :class:`robots.thermal.drift.DriftTruth`). The measured positions get
    Gaussian noise of ``noise_m`` (m) per axis.
    """
    times = np.asarray(times_s, dtype=float)
    ids = [tid for _ in times for tid, _q in plan]
    q = np.array([np.asarray(qq, dtype=float) for _ in times for _t, qq in plan]).reshape(-1, 6)
    t = np.repeat(times, len(plan))
    T = T_base_tool0_at(q, t)
    p = predict_p_tcp(T, geometry.T_tool0_tcp, geometry.targets_base_m(ids))
    if noise_m > 0:
        p = p + np.random.default_rng(seed).normal(0.0, noise_m, p.shape)
    temps = np.asarray(sensor_readings_at(t), dtype=float)
    return Observations(
        time_s=t,
        target_ids=tuple(ids),
        q_rad=q,
        temps_degC=temps.reshape(len(t), len(sensor_names)),
        sensor_names=tuple(sensor_names),
        p_tcp_m=p,
        source="simulation",
    )
