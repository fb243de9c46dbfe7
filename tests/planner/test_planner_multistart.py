"""Multi-start: independent starts in fresh processes; the same seeds give the same best tour
on any engine (local processes one or two at a time, a local Ray instance)."""

from __future__ import annotations

import sys

import numpy as np
import pytest
import yaml

from cell.config import builtin_cell_path, parse_cell
from planner import Options
from planner.engines import LocalEngine, RayEngine
from planner.errors import EngineError, StartsFailedError
from planner.multistart import best_tour, plan_multistart, start_seeds


def _cell(n_holes: int = 3):
    data = yaml.safe_load(builtin_cell_path().read_text())
    data["name"] = "multistart-test"
    data["part"]["holes"] = data["part"]["holes"][:n_holes]
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
