"""Multi-start: independent starts in fresh processes; the same seeds give the same best tour
on any engine (local processes one or two at a time, a local Ray instance)."""

from __future__ import annotations

import sys

import numpy as np
import pytest
import yaml

from cell.config import builtin_cell_path, parse_cell
from cell.config.datums import without_drawing
from planner import Options
from planner.engines import LocalEngine, RayEngine
from planner.errors import EngineError, PlanningError, StartsFailedError
from planner.multistart import best_tour, plan_multistart, start_seeds
from planner.planner import TourPlanner
from planner.shared import pack


def _cell(n_holes: int = 3):
    data = yaml.safe_load(builtin_cell_path().read_text())
    data["name"] = "multistart-test"
    data["part"]["holes"] = data["part"]["holes"][:n_holes]
    without_drawing(data, 5e-5)  # the subset may leave datum features out
    return parse_cell(yaml.safe_dump(data), "<multistart test>")


def test_start_seeds_of_two_base_seeds_never_overlap() -> None:
    assert start_seeds(Options(seed=0), 3) == [0, 1, 2]
    assert start_seeds(Options(seed=2), 3) == [6, 7, 8]


def test_starts_run_in_local_processes_and_the_shortest_tour_is_kept() -> None:
    a = plan_multistart(_cell(), Options(seed=1), 2, LocalEngine(2))
    assert a.settings["start_seeds"] == [2, 3] and a.settings["engine"].startswith("local")
    times = a.settings["start_cycle_times_s"]
    assert a.cycle_time_s == min(times)
    assert a.settings["seed"] == [2, 3][times.index(min(times))]
    assert a.settings["cpu_time_s"] > 0 and len(a.stops) == 3


def test_every_start_failing_raises_the_planning_error() -> None:
    with pytest.raises(StartsFailedError, match="out of reach"):
        best_tour(["UnreachableHoleError: 1 hole(s) cannot be inspected: X: out of reach"], [0])


def test_ray_missing_is_a_one_line_error(monkeypatch) -> None:
    monkeypatch.setitem(sys.modules, "ray", None)  # import ray raises ImportError
    with pytest.raises(EngineError, match=r"Ray is not installed.*holecell\[ray\]"):
        RayEngine("local")


@pytest.mark.ray
def test_a_local_ray_instance_gives_the_same_best_tour_as_local_processes() -> None:
    ray = pytest.importorskip("ray")
    cell = _cell()
    local = plan_multistart(cell, Options(seed=1), 2, LocalEngine(2))
    try:
        on_ray = plan_multistart(cell, Options(seed=1), 2, RayEngine("local", num_cpus=2))
    finally:
        ray.shutdown()
    assert on_ray.settings["engine"].startswith("ray")
    assert on_ray.settings["start_cycle_times_s"] == local.settings["start_cycle_times_s"]
    assert np.array_equal(on_ray.trajectory, local.trajectory)


def test_a_start_handed_the_shared_part_gives_the_same_tour_as_one_that_computed_it() -> None:
    cell = _cell(4)
    engine = LocalEngine(2)
    shared = plan_multistart(cell, Options(seed=3), 2, engine, share=True)
    alone = plan_multistart(cell, Options(seed=3), 2, engine, share=False)
    assert shared.settings["shared"] and not alone.settings["shared"]
    assert shared.settings["shared_bytes"] > 0
    assert shared.settings["start_cycle_times_s"] == alone.settings["start_cycle_times_s"]
    assert np.array_equal(shared.trajectory, alone.trajectory)
    assert shared.settings["collision_checks"] == alone.settings["collision_checks"]
    # the shared part's own work is not counted again in the start's CPU time
    assert shared.settings["cpu_time_s"] < alone.settings["cpu_time_s"]
    # ... and in this process (no OMPL segment on these holes: its seed is per process)
    here = TourPlanner(Options(seed=6)).plan(cell)
    assert here.settings["ompl_segments"] == 0
    assert here.cycle_time_s == shared.settings["start_cycle_times_s"][0]


def test_the_shared_part_of_another_cell_or_other_options_is_refused() -> None:
    cell = _cell(2)
    shared = TourPlanner(Options(seed=0)).prepare(cell)
    # another seed is what the shared part is for
    tour = TourPlanner(Options(seed=5)).plan(cell, pack(shared))
    assert len(tour.stops) == 2
    with pytest.raises(PlanningError, match="other roll_step_deg"):
        TourPlanner(Options(roll_step_deg=30.0)).plan(cell, shared)
    with pytest.raises(PlanningError, match="another cell"):
        TourPlanner(Options()).plan(_cell(3), shared)
