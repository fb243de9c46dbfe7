"""A run as a ROS 2 bag (MCAP): the tour it drove (``/joint_trajectory``,
``/display_planned_path``, ``/joint_states`` at 100 Hz, ``/inspection/stops``, as
:mod:`cell.ros.tour_bag`), the joint state the arm reported at each capture
(``/inspection/capture_states``, at the stop's time in the tour) and each measured hole in
the cell frame (``/inspection/holes``: a disc of the measured diameter on the measured axis,
green when it passed, red when not). Runs keep no stereo images, so the bag has none."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np

from cell.gdt.report_fields import run_cell
from cell.review.store import Store
from cell.ros.markers import hole_markers
from cell.ros.msgs import JOINT_STATE, MARKER_ARRAY, typestore
from cell.ros.samples import header, make
from cell.ros.tour_bag import write_tour_bag
from planner.tour import tour_from_dict

CAPTURES = "/inspection/capture_states"
HOLES = "/inspection/holes"


def _measured(results: list[Any], T_cell_part: np.ndarray) -> list[dict[str, Any]]:
    out = []
    for r in results:
        if r.center_part_m is None or r.normal_part is None or r.diameter_m is None:
            continue
        dev = "" if r.position_deviation_m is None else f" {r.position_deviation_m * 1e3:.3f} mm"
        out.append(
            {
                "center_m": T_cell_part[:3, :3] @ np.array(r.center_part_m) + T_cell_part[:3, 3],
                "normal": T_cell_part[:3, :3] @ np.array(r.normal_part),
                "diameter_m": r.diameter_m,
                "passed": r.passed,
                "label": f"{r.hole_id}{dev}",
            }
        )
    return out


def write_run_bag(run_dir: str | Path, out: str | Path, overwrite: bool = False) -> dict[str, int]:
    """Write the run in ``run_dir`` as a bag in folder ``out``; messages per topic."""
    with Store.open(run_dir) as store_db:
        info = store_db.run_info()
        results = store_db.results()
    tour = tour_from_dict(json.loads(info["tour_text"]), f"{run_dir} (the run's tour)")
    cfg = run_cell(info)
    store = typestore()
    stop_t = {s.hole_id: s.t for s in tour.stops}
    captures = [
        (
            round(stop_t.get(r.hole_id, 0.0) * 1e9),
            make(
                store,
                JOINT_STATE,
                header=header(store, round(stop_t.get(r.hole_id, 0.0) * 1e9), r.hole_id),
                name=list(tour.joint_names),
                position=np.array(r.q_rad, dtype=np.float64),
            ),
        )
        for r in results
        if len(r.q_rad) == len(tour.joint_names)
    ]
    holes = _measured(results, cfg.T_cell_part())
    end_ns = round(tour.cycle_time_s * 1e9)
    return write_tour_bag(
        tour,
        out,
        standoff_m=cfg.tool.standoff_m,
        T_cell_base=cfg.T_cell_base(),
        overwrite=overwrite,
        extra=[
            (CAPTURES, JOINT_STATE, sorted(captures, key=lambda c: c[0])),
            (HOLES, MARKER_ARRAY, [(end_ns, hole_markers(store, holes, end_ns))]),
        ],
    )
