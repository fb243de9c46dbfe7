"""A marker layout for a cell: dots stuck on the part around every hole, dots on the table
around the fixture, and two scale bars; and the check that every hole's stop sees enough of
them (``holecell cell show``).

Part markers: around each hole, four dots at ``ring_m`` from its centre in its plane (diagonal
to the hole's tangent axes), kept ``min_gap_m`` from every other marker and clear of every hole;
a hole group shares its neighbours' dots. Fixture markers: a grid on the table top (normal +z).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from cell.config import CellConfig
from cell.config.markers import marker_in_cell
from cell.referencing.observations import project
from cell.referencing.visibility import seen, well_spread
from measure import StereoCalibration
from measure.head import head_frame
from robots.transforms import frame_from_z_axis, invert

Array = NDArray[np.float64]


@dataclass(frozen=True)
class LayoutOptions:
    """Where :func:`suggest_markers` puts dots (m)."""

    ring_m: float = 0.03
    dot_m: float = 0.005
    min_gap_m: float = 0.02
    hole_clearance_m: float = 0.008
    table_z_m: float = 0.38
    table_x_m: tuple[float, ...] = (0.80, 0.92, 1.24, 1.36)
    table_y_m: tuple[float, ...] = (-0.7, -0.525, -0.35, -0.175, 0.0, 0.175, 0.35, 0.525, 0.7)


def _tangents(n: Array) -> tuple[Array, Array]:
    T = frame_from_z_axis(np.zeros(3), n)
    return T[:3, 0], T[:3, 1]


def _entry(mid: str, pos: list[float], nrm: list[float], dot_m: float, on: str) -> dict:
    return {"id": mid, "position": pos, "normal": nrm, "diameter_m": dot_m, "on": on}


def suggest_markers(cell: CellConfig, options: LayoutOptions | None = None) -> list[dict]:
    """Marker entries (the cell file's ``reference_markers`` form) for ``cell`` (module doc)."""
    o = options or LayoutOptions()
    holes = [
        (np.array(h.position, float), np.array(h.normal, float), h.diameter)
        for h in cell.part.holes
    ]
    placed: list[Array] = []
    out: list[dict] = []
    for p, n, _d in holes:
        u, v = _tangents(n)
        for k in range(4):
            a = math.pi / 4 + k * math.pi / 2
            q = p + o.ring_m * (math.cos(a) * u + math.sin(a) * v)
            if any(np.linalg.norm(q - r) < o.min_gap_m for r in placed):
                continue
            if any(
                np.linalg.norm(q - hp) < hd / 2 + o.dot_m / 2 + o.hole_clearance_m
                for hp, _, hd in holes
            ):
                continue
            placed.append(q)
            pos, nrm = [round(float(x), 4) for x in q], [round(float(x), 4) for x in n]
            out.append(_entry(f"P{len(placed):03d}", pos, nrm, o.dot_m, "part"))
    k = 0
    for x in o.table_x_m:
        for y in o.table_y_m:
            k += 1
            pos = [x, y, o.table_z_m]
            out.append(_entry(f"T{k:02d}", pos, [0.0, 0.0, 1.0], 2 * o.dot_m, "fixture"))
    return out


def stop_pose(
    cell: CellConfig, stereo: StereoCalibration, hole_id: str, roll_rad: float = 0.0
) -> Array:
    """The left camera's pose (4, 4) in the cell at hole ``hole_id``'s nominal viewpoint (TCP on
    the hole's axis at the standoff, looking into the hole, rolled by ``roll_rad``)."""
    h = next(h for h in cell.holes_in_cell() if h.id == hole_id)
    T_cell_tcp = frame_from_z_axis(
        h.position_m + cell.tool.standoff_m * h.normal, -h.normal, roll_rad
    )
    return T_cell_tcp @ invert(head_frame(stereo))


def markers_seen_per_hole(cell: CellConfig, stereo: StereoCalibration) -> dict[str, list[str]]:
    """Per hole, the markers its nominal stop sees in both cameras (the worse of roll 0 and
    90 deg), empty when they are fewer than 4 or not well spread."""
    ms = cell.reference_markers
    T_cell_part = cell.T_cell_part()
    placed = [marker_in_cell(m, T_cell_part) for m in ms]
    P = np.array([p for p, _ in placed]).reshape(-1, 3)
    N = np.array([n for _, n in placed]).reshape(-1, 3)
    out = {}
    for h in cell.part.holes:
        worst: list[str] | None = None
        for roll in (0.0, math.pi / 2):
            T = stop_pose(cell, stereo, h.id, roll)
            mask = seen(stereo, T, P, N)
            ids = [m.id for m, ok in zip(ms, mask, strict=True) if ok]
            uv = project(stereo, "left", invert(T), P[mask]) if mask.any() else np.zeros((0, 2))
            if not well_spread(stereo, uv):
                ids = []
            worst = ids if worst is None or len(ids) < len(worst) else worst
        out[h.id] = worst or []
    return out
