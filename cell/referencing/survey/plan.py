"""The survey's views (geometry only): converging views of every hole's markers at two
distances, rolls alternating 0 and 90 deg, and views of the table's markers from above, so that
each marker is seen from directions well apart and the network is one piece.

Near views: ``near_m`` from the hole, the view axis tilted ``tilt_rad`` from the hole's normal
at three azimuths; far views: ``far_m`` along the normal. Views aimed within ``merge_m`` of one
already planned, along a direction within 10 deg of its, are dropped (a hole group shares them).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from cell.config import CellConfig
from cell.config.markers import marker_in_cell
from measure import StereoCalibration
from measure.head import head_frame
from robots.transforms import frame_from_z_axis, invert

Array = NDArray[np.float64]


@dataclass(frozen=True)
class SurveyPlanOptions:
    near_m: float = 0.30
    far_m: float = 0.60
    tilt_rad: float = math.radians(25.0)
    table_m: float = 1.0
    merge_m: float = 0.04
    overview_m: float = 0.9
    overview_grid_m: float = 0.2
    #: directions the overview views look from (cell frame, normalised): from the robot's side,
    #: left, right and above
    overview_from: tuple[tuple[float, float, float], ...] = (
        (-1.0, 0.0, 0.3),
        (-1.0, 0.5, 0.6),
        (-1.0, -0.5, 0.6),
        (-0.4, 0.0, 1.0),
    )


def _tilted(n: Array, tilt: float, azimuth: float) -> Array:
    T = frame_from_z_axis(np.zeros(3), n)
    u, v = T[:3, 0], T[:3, 1]
    d = math.cos(tilt) * n + math.sin(tilt) * (math.cos(azimuth) * u + math.sin(azimuth) * v)
    return d / np.linalg.norm(d)


def survey_views(
    cell: CellConfig, stereo: StereoCalibration, options: SurveyPlanOptions | None = None
) -> list[tuple[str, Array]]:
    """``(view id, T_cell_left)`` of the survey's views (module doc)."""
    o = options or SurveyPlanOptions()
    T_head_left = invert(head_frame(stereo))
    planned: list[tuple[Array, Array]] = []
    out: list[tuple[str, Array]] = []

    def add(name: str, aim: Array, direction: Array, dist: float, roll: float) -> None:
        for a, d in planned:
            if np.linalg.norm(a - aim) < o.merge_m and float(d @ direction) > math.cos(
                math.radians(10)
            ):
                return
        planned.append((aim, direction))
        T_cell_tcp = frame_from_z_axis(aim + dist * direction, -direction, roll)
        out.append((name, T_cell_tcp @ T_head_left))

    for h in cell.holes_in_cell():
        add(f"{h.id}-far", h.position_m, h.normal, o.far_m, 0.0)
        for k in range(3):
            d = _tilted(h.normal, o.tilt_rad, 2 * math.pi * k / 3)
            add(f"{h.id}-near{k}", h.position_m, d, o.near_m, (k % 2) * math.pi / 2)
    T_cell_part = cell.T_cell_part()
    _overview(cell, o, add)
    toward_robot = np.array([-1.0, 0.0, 1.0]) / math.sqrt(2.0)
    for m in cell.reference_markers:
        if m.on == "fixture":
            p, n = marker_in_cell(m, T_cell_part)
            add(f"{m.id}-above", p, n, o.table_m, 0.0)
            add(f"{m.id}-slant", p, toward_robot, o.table_m, math.pi / 2)
    return out


def _overview(cell: CellConfig, o: SurveyPlanOptions, add) -> None:
    """Views from ``overview_m`` aimed at a grid over the markers' extent, from each of
    ``overview_from``: each camera alone sees a large piece, which ties the hole groups
    together and to the fixture."""
    T_cell_part = cell.T_cell_part()
    P = np.array([marker_in_cell(m, T_cell_part)[0] for m in cell.reference_markers])
    if len(P) == 0:
        return
    lo, hi = P.min(axis=0), P.max(axis=0)
    axes = [np.arange(lo[k], hi[k] + o.overview_grid_m / 2, o.overview_grid_m) for k in range(3)]
    for k, d in enumerate(o.overview_from):
        direction = np.asarray(d, float) / np.linalg.norm(d)
        for x in axes[0]:
            for y in axes[1]:
                for z in axes[2]:
                    aim = np.array([x, y, z])
                    if np.min(np.linalg.norm(P - aim, axis=1)) < o.overview_grid_m:
                        add(
                            f"overview{k}-{x:.2f},{y:.2f},{z:.2f}",
                            aim,
                            direction,
                            o.overview_m,
                            (k % 2) * math.pi / 2,
                        )
