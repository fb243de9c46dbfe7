"""plan_tour on the built-in motorcycle frame and on small hand-built cells."""

from __future__ import annotations

import hashlib
from pathlib import Path

import numpy as np
import pytest
import yaml

from cell.config import builtin_cell_path, load_builtin_cell, parse_cell
from cell.config.datums import without_drawing
from planner import (
    Options,
    Tour,
    TourCellMismatchError,
    UnreachableHoleError,
    check_tour_for_cell,
    load_tour,
    plan_tour,
)
from planner.timing import JointLimits
from planner.trajectory import finite_difference_limits
from planner.viewpoints import hole_candidates

#: finite differences of the sampled trajectory may exceed a limit by this fraction (rounding)
LIMIT_TOL = 1e-6


@pytest.fixture(scope="module")
def builtin() -> tuple[object, Tour]:
    cell = load_builtin_cell()
    return cell, plan_tour(cell, Options(seed=0))


def _small_cell(extra_holes: list[dict], keep: int = 4) -> object:
    data = yaml.safe_load(builtin_cell_path().read_text())
    data["name"] = "small-test-cell"
    data["part"]["holes"] = data["part"]["holes"][:keep] + extra_holes
    without_drawing(data, 5e-5)  # the subset may leave datum features out
    return parse_cell(yaml.safe_dump(data), "<small-test-cell>")


FAR = {"id": "FAR", "position": [4.0, 0.0, 0.0], "normal": [0, 0, 1], "diameter": 0.01}
#: inside the fixture table, facing the robot: the head would sit inside the table
UNDER = {"id": "UNDER", "position": [0.0, 0.0, -0.44], "normal": [0, 1, 0], "diameter": 0.01}


def test_every_reachable_hole_is_visited_once(builtin) -> None:
    cell, tour = builtin
    ids = [h.id for h in cell.holes_in_cell()]
    visited = tour.hole_order
    assert len(visited) == len(set(visited))
    assert sorted(visited + [h.hole_id for h in tour.left_out]) == sorted(ids)
    assert len(visited) >= 40


def test_each_stop_puts_the_tcp_on_the_hole_axis_at_the_standoff(builtin) -> None:
    cell, tour = builtin
    arm = cell.build_arm()
    holes = {h.id: h for h in cell.holes_in_cell()}
    for stop in tour.stops:
        h = holes[stop.hole_id]
        T = arm.fk(np.array(stop.q), "tcp")
        z = T[:3, 2]
        assert np.linalg.norm(T[:3, 3] + cell.tool.standoff_m * z - h.position_m) < 1e-6
        if z @ -h.normal != pytest.approx(1.0, abs=1e-9):
            # off the axis only on the fallback cone, where no view along the axis is free
            assert z @ -h.normal == pytest.approx(np.cos(np.radians(10.0)), abs=1e-9)
            assert not hole_candidates(arm, h, cell.tool.standoff_m, 15.0).ok
        assert np.allclose(stop.tcp_pose["xyz"], T[:3, 3])


def test_trajectory_within_limits_collision_free_and_through_the_stops(builtin) -> None:
    cell, tour = builtin
    arm = cell.build_arm()
    q = tour.trajectory
    assert np.allclose(q[0], tour.home_q) and np.allclose(q[-1], tour.home_q)
    report = finite_difference_limits(q, tour.dt, JointLimits.from_arm(arm))
    assert report.within(LIMIT_TOL), report
    assert not any(arm.in_collision(row) for row in q)
    for stop in tour.stops:  # at rest on the stop during its dwell
        k = int(np.ceil(stop.t / tour.dt))
        assert np.allclose(q[k], stop.q, atol=1e-9)
    assert tour.cycle_time_s == pytest.approx((len(q) - 1) * tour.dt, abs=tour.dt)
    assert tour.cycle_time_s == pytest.approx(tour.stops[-1].t + 0.2 + _last_leg(tour), rel=1e-9)


def _last_leg(tour: Tour) -> float:
    return tour.cycle_time_s - tour.stops[-1].t - tour.stops[-1].dwell_s


def test_same_seed_gives_the_same_tour(builtin) -> None:
    cell, tour = builtin
    again = plan_tour(cell, Options(seed=0))
    assert again.hole_order == tour.hole_order
    assert [s.q for s in again.stops] == [s.q for s in tour.stops]


def test_tour_file_identifies_the_cell_and_round_trips(builtin, tmp_path: Path) -> None:
    cell, tour = builtin
    back = load_tour(tour.save(tmp_path / "tour.json"))
    assert back.cell_sha256 == hashlib.sha256(cell.raw_text.encode()).hexdigest()
    assert back.cell_name == cell.name and back.robot_model == cell.robot.model
    assert back.hole_order == tour.hole_order
    assert np.array_equal(back.trajectory, tour.trajectory)
    assert set(tour.timings_s) == {"viewpoints", "sequence", "paths", "timing"}


def test_a_tour_is_refused_for_another_cell(builtin) -> None:
    cell, tour = builtin
    check_tour_for_cell(tour, cell)
    other = _small_cell([], keep=3)
    with pytest.raises(TourCellMismatchError, match="cell name"):
        check_tour_for_cell(tour, other)
    data = yaml.safe_load(cell.raw_text)
    data["part"]["holes"][0]["position"][0] += 0.001  # same name, moved hole
    moved = parse_cell(yaml.safe_dump(data), "<moved>")
    with pytest.raises(TourCellMismatchError, match="sha256"):
        check_tour_for_cell(tour, moved)


def test_unreachable_and_colliding_holes_are_left_out_with_reasons() -> None:
    cell = _small_cell([FAR, UNDER])
    tour = plan_tour(cell, Options(seed=1))
    reasons = {h.hole_id: h.reason for h in tour.left_out}
    assert set(reasons) == {"FAR", "UNDER"}
    assert "out of reach" in reasons["FAR"]
    assert "in collision" in reasons["UNDER"]
    assert tour.status == "partial" and len(tour.stops) == 4


def test_strict_mode_refuses_a_cell_with_unreachable_holes() -> None:
    cell = _small_cell([FAR], keep=2)
    with pytest.raises(UnreachableHoleError, match="FAR: out of reach") as err:
        plan_tour(cell, Options(strict=True))
    assert set(err.value.reasons) == {"FAR"}


def test_tilt_cone_and_progress_callback() -> None:
    cell = _small_cell([], keep=3)
    seen: list[tuple[str, int, int]] = []
    tour = plan_tour(
        cell, Options(tilt_deg=10.0, tilt_azimuths=4), progress=lambda *a: seen.append(a)
    )
    stages = list(dict.fromkeys(stage for stage, _, _ in seen))
    assert stages == ["viewpoints", "sequence", "paths", "timing"]
    assert all(0 <= done <= total for _, done, total in seen)
    arm = cell.build_arm()
    holes = {h.id: h for h in cell.holes_in_cell()}
    for stop in tour.stops:
        T = arm.fk(np.array(stop.q), "tcp")
        h = holes[stop.hole_id]
        assert np.linalg.norm(T[:3, 3] + cell.tool.standoff_m * T[:3, 2] - h.position_m) < 1e-6
        assert T[:3, 2] @ -h.normal >= np.cos(np.radians(10.0)) - 1e-9
