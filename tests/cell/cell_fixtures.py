"""Shared fixtures of the cell tests: a small cell (three holes of the built-in frame, written to
a file) and its planned tours, planned once per session. A uniquely named module (test modules
import from it; ``conftest.py`` re-exports the fixture), so it never collides with another
directory's ``conftest``."""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import pytest
import yaml

from cell.config import CellConfig, builtin_cell_path, load_cell
from cell.config.datums import without_drawing
from cell.run.reference import plan_reference_tour
from planner import Options, Tour, plan_tour
from robots.thermal.drift import DriftSettings, WarmUp

N_HOLES = 3


@dataclass
class SmallCell:
    """A three-hole cell file, its tour (also as a file) and its reference tour."""

    path: Path
    cell: CellConfig
    tour: Tour
    tour_path: Path
    reference: Tour


@pytest.fixture(scope="session")
def small_cell(tmp_path_factory: pytest.TempPathFactory) -> SmallCell:
    root = tmp_path_factory.mktemp("small_cell")
    data = yaml.safe_load(builtin_cell_path().read_text())
    data["name"] = "small_frame"
    data["part"]["holes"] = data["part"]["holes"][:N_HOLES]
    without_drawing(data, 5e-5)  # the subset may leave datum features out
    path = root / "small.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    cell = load_cell(path)
    tour = plan_tour(cell, Options(seed=1))
    tour_path = tour.save(root / "tour.json")
    return SmallCell(path, cell, tour, tour_path, plan_reference_tour(cell, Options(seed=1)))


def steady_drift() -> DriftSettings:
    """An arm that does not warm up and sensors without noise: runs repeat bit for bit."""
    return DriftSettings.per_joint(("steel",) * 6, (WarmUp(0.0, 100.0),) * 6)


@pytest.fixture(params=["python", "rapid"])
def controller(request: pytest.FixtureRequest) -> str:
    """The simulated controller: the Python stand-in or the shipped RAPID module interpreted."""
    return request.param


@pytest.fixture(params=["python", pytest.param("rapid", marks=pytest.mark.slow)])
def controller_rapid_slow(request: pytest.FixtureRequest) -> str:
    """As ``controller``, the interpreted module only with ``-m slow`` (a long test)."""
    return request.param


def link_for(controller: str, options):
    """The test's link options; against the interpreted module a response timeout of at least
    the client's default (it answers a full LOAD_ROWS frame in tens of ms)."""
    from dataclasses import replace

    if controller != "rapid":
        return options
    return replace(options, response_timeout_s=max(options.response_timeout_s, 0.15))


@pytest.fixture(scope="session", autouse=True)
def private_cache(tmp_path_factory: pytest.TempPathFactory):
    """holecell's cache folder is a temporary one in these tests (the demo's calibration tour
    is planned once and read back as in use, but never from or into the user's cache)."""
    from measure.user_cache import CACHE_ENV

    before = os.environ.get(CACHE_ENV)
    os.environ[CACHE_ENV] = str(tmp_path_factory.mktemp("holecell-cache"))
    yield
    if before is None:
        os.environ.pop(CACHE_ENV, None)
    else:
        os.environ[CACHE_ENV] = before
