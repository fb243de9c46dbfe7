"""The demo's calibration tour, planned once and read back from the cache folder."""

from __future__ import annotations

import json

import numpy as np
import pytest

from cell.calibration.plan import CalibrationPlanOptions, TargetGeometry, plan_calibration
from cell.camera import cell_stereo
from cell.config import load_builtin_cell
from cell.demo.caltour_cache import cached_caltour, caltour_key
from measure.user_cache import CACHE_ENV, cache_dir
from planner import Options
from robots.transforms import make_transform, rpy_to_matrix

TARGET = TargetGeometry(
    "chessboard", 9, 7, 0.01, make_transform(rpy_to_matrix([np.pi, 0, 0]), [0.9, -0.45, 0.381])
)


@pytest.fixture(scope="module")
def planned():
    """A real five-view calibration tour of the built-in cell, and how often it was planned."""
    cell = load_builtin_cell()
    stops = np.array([cell.home_q(), cell.home_q() + 0.3])
    o = CalibrationPlanOptions(views=5, criterion="geometric", tour=Options(seed=1))
    calls = []

    def plan():
        calls.append(1)
        return plan_calibration(cell, TARGET, cell_stereo(cell), stops, o).to_dict()

    return cell, o, plan, calls


def test_planned_once_then_read_back(planned, tmp_path) -> None:
    cell, o, plan, calls = planned
    key = caltour_key(cell, o, 5, 1)
    n0 = len(calls)
    first, note1 = cached_caltour(key, plan, tmp_path)
    assert len(calls) == n0 + 1 and note1.startswith("planned in") and "cached in" in note1
    again, note2 = cached_caltour(key, plan, tmp_path)
    assert len(calls) == n0 + 1 and note2.startswith("from the cache")
    assert again == json.loads(json.dumps(first))
    # a file that does not read back as a calibration tour is planned over
    (path,) = tmp_path.glob("caltour-*.json")
    path.write_text('{"format": "not a tour"}')
    third, note3 = cached_caltour(key, plan, tmp_path)
    assert len(calls) == n0 + 2 and "did not read back" in note3
    assert third["calibration"]["views"] == first["calibration"]["views"]
    assert third["stops"] == first["stops"]  # deterministic: the same tour planned again


def test_an_unwritable_cache_costs_the_cache_only(planned, tmp_path) -> None:
    cell, o, plan, _ = planned
    blocked = tmp_path / "file"
    blocked.write_text("a file where the folder should be")
    data, note = cached_caltour(caltour_key(cell, o, 5, 1), plan, blocked)
    assert "not cached" in note and data["calibration"]["views"]


def test_the_key_names_what_decides_the_plan(planned, monkeypatch, tmp_path) -> None:
    cell, o, _, _ = planned
    key = caltour_key(cell, o, 5, 1)
    assert key == caltour_key(cell, o, 5, 1) and len(key) == 64
    assert len({key, caltour_key(cell, o, 6, 1), caltour_key(cell, o, 5, 2)}) == 3
    monkeypatch.setenv(CACHE_ENV, str(tmp_path))
    assert cache_dir() == tmp_path


def test_the_cache_alone_is_read_without_planning(planned, tmp_path) -> None:
    """``plan`` None (the demo looking before it starts a worker): None on a miss, nothing
    planned or written; the cached tour once it is there."""
    cell, o, plan, calls = planned
    key = caltour_key(cell, o, 5, 1)
    n0 = len(calls)
    assert cached_caltour(key, None, tmp_path) is None
    assert len(calls) == n0 and not list(tmp_path.iterdir())
    first, _ = cached_caltour(key, plan, tmp_path)
    again, note = cached_caltour(key, None, tmp_path)
    assert len(calls) == n0 + 1 and note.startswith("from the cache") and again == json.loads(
        json.dumps(first))  # fmt: skip
