"""The tour planner with the markers in view: viewpoints whose stop sees fewer than 4
well-spread markers are dropped; a hole with none that does is kept and named."""

from __future__ import annotations

import numpy as np
import yaml
from referencing_cells import small_cell_text

from cell.camera import cell_stereo
from cell.config import builtin_cell_path, parse_cell
from cell.referencing.viewpoints import MarkerAwarePlanner, poses_seeing_markers
from planner import Options
from planner.viewpoints import viewpoint_poses


def test_only_viewpoints_that_see_the_markers_are_kept(small_cell) -> None:
    stereo = cell_stereo(small_cell)
    h = small_cell.holes_in_cell()[0]
    poses = viewpoint_poses(h.position_m, h.normal, small_cell.tool.standoff_m, 30.0)
    assert poses_seeing_markers(small_cell, stereo, poses).all()
    away = poses.copy()  # the same stops turned to look away from the part
    away[:, :3, :3] = away[:, :3, :3] @ np.diag([1.0, -1.0, -1.0])
    assert not poses_seeing_markers(small_cell, stereo, away).any()


def test_a_hole_without_markers_in_view_is_planned_and_named() -> None:
    data = yaml.safe_load(small_cell_text())
    first = data["part"]["holes"][0]
    p = np.array(first["position"], float)
    data["reference_markers"] = [
        m for m in data["reference_markers"]
        if m["on"] != "part" or np.linalg.norm(np.array(m["position"]) - p) > 0.08
    ]  # fmt: skip
    cell = parse_cell(yaml.safe_dump(data), "small.yaml", builtin_cell_path())
    planner = MarkerAwarePlanner(cell, cell_stereo(cell), Options(seed=1))
    tour = planner.plan(cell)
    assert first["id"] in planner.without_markers
    assert first["id"] in tour.hole_order and len(tour.hole_order) == len(data["part"]["holes"])
