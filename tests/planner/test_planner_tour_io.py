"""tour.json: round trip and clear errors for malformed files."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from planner.errors import TourFileError
from planner.tour import LeftOut, Stop, Tour, load_tour


def _tour() -> Tour:
    q = (0.1, -0.2, 0.3, 0.0, 1.0, -0.5)
    stop = Stop("H1", q, 1.25, 0.2, {"xyz": [1.0, 0.0, 0.5], "quat_xyzw": [0.0, 0.0, 0.0, 1.0]}, 3)
    return Tour(
        cell_name="test-cell",
        cell_sha256="ab" * 32,
        robot_model="abb_irb2600_20_165",
        joint_names=tuple(f"joint_{i}" for i in range(1, 7)),
        home_q=(0.0,) * 6,
        stops=[stop],
        left_out=[LeftOut("H9", "out of reach")],
        dt=0.004,
        trajectory=np.linspace(0, 1, 60).reshape(10, 6),
        cycle_time_s=3.0,
        planning_time_s=0.5,
        timings_s={"viewpoints": 0.1},
        settings={"seed": 3},
    )


def test_round_trip_keeps_every_field(tmp_path: Path) -> None:
    tour = _tour()
    path = tour.save(tmp_path / "tour.json")
    back = load_tour(path)
    assert back.to_dict() == tour.to_dict()
    assert back.status == "partial" and back.hole_order == ["H1"]
    assert np.array_equal(back.trajectory, tour.trajectory)
    data = json.loads(path.read_text())
    assert data["cell"] == {"name": "test-cell", "sha256": "ab" * 32}
    assert data["left_out"] == [{"hole_id": "H9", "reason": "out of reach"}]


@pytest.mark.parametrize(
    ("edit", "field"),
    [
        (lambda d: d.pop("stops"), "stops"),
        (lambda d: d["stops"][0].update(q=[1, 2]), "stops[0].q"),
        (lambda d: d.update(trajectory=[[0, 1]]), "trajectory"),
        (lambda d: d.update(dt=-1), "dt"),
        (lambda d: d.update(format="other"), "format"),
        (lambda d: d["left_out"][0].pop("reason"), "reason"),
    ],
)
def test_malformed_files_name_the_file_and_field(tmp_path: Path, edit, field: str) -> None:
    data = _tour().to_dict()
    edit(data)
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(data))
    with pytest.raises(TourFileError, match=field.replace("[", r"\[").replace("]", r"\]")) as err:
        load_tour(path)
    assert str(path) in str(err.value)


def test_missing_and_non_json_files(tmp_path: Path) -> None:
    with pytest.raises(TourFileError, match="not found"):
        load_tour(tmp_path / "nope.json")
    (tmp_path / "x.json").write_text("{not json")
    with pytest.raises(TourFileError, match="not readable"):
        load_tour(tmp_path / "x.json")


def test_saving_over_an_existing_file_replaces_it_whole(tmp_path: Path) -> None:
    path = tmp_path / "tour.json"
    path.write_text("old")
    _tour().save(path)
    assert load_tour(path).cell_name == "test-cell"
    assert not (tmp_path / "tour.json.tmp").exists()
