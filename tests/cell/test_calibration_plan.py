"""holecell plan-calibration: the calibration tour of a cell (cell.calibration.plan)."""

from __future__ import annotations

import numpy as np
import pytest
import yaml

from cell.calibration.plan import (
    CalibrationPlanOptions,
    TargetGeometry,
    joint_range,
    plan_calibration,
)
from cell.camera import cell_stereo
from cell.cli import main
from cell.config import builtin_cell_path, load_builtin_cell
from cell.errors import CellError
from planner import Options
from planner.calibration import load_caltour
from robots.transforms import make_transform, rpy_to_matrix

#: a target we place ourselves: flat on the fixture table beside the part
TARGET = TargetGeometry(
    "chessboard", 9, 7, 0.01, make_transform(rpy_to_matrix([np.pi, 0, 0]), [0.9, -0.45, 0.381])
)


@pytest.fixture(scope="module")
def cell():
    return load_builtin_cell()


def test_geometric_plan_of_a_placed_target(cell, tmp_path, capsys) -> None:
    stops = np.array([cell.home_q(), cell.home_q() + 0.3])
    o = CalibrationPlanOptions(views=5, criterion="geometric", tour=Options(seed=1))
    cal = plan_calibration(cell, TARGET, cell_stereo(cell), stops, o)
    assert len(cal.tour.stops) == 5 and not cal.tour.left_out
    assert cal.design["min_rotation_rad"] > np.radians(20)
    assert cal.tour.cycle_time_s < 180
    lo, hi = joint_range(stops)
    assert cal.design["joint_range_rad"] == [lo.tolist(), hi.tolist()]
    back = load_caltour(cal.save(tmp_path / "caltour.json"))
    assert back.target["pattern"] == "chessboard" and back.target["cols"] == 9
    assert {v["id"] for v in back.views} == {s.hole_id for s in back.tour.stops}
    # a calibration tour is no hole tour: its stops are no holes of the cell
    hole_tour = cal.tour.save(tmp_path / "tour.json")
    args = ["plan-calibration", "-o", str(tmp_path / "c.json"), "--tour", str(hole_tour)]
    assert main([*args, "--quiet"]) == 2
    assert "CAL01" in capsys.readouterr().err


def test_more_views_than_feasible_are_refused(cell) -> None:
    o = CalibrationPlanOptions(views=5000, criterion="geometric")
    with pytest.raises(CellError, match="feasible view"):
        plan_calibration(cell, TARGET, cell_stereo(cell), np.array([cell.home_q()]), o)


def test_bad_options_are_refused() -> None:
    with pytest.raises(CellError, match="criterion"):
        CalibrationPlanOptions(criterion="e")
    with pytest.raises(CellError, match="corner_sigma_px"):
        CalibrationPlanOptions(corner_sigma_px=0.0)


def test_cli_plans_the_builtin_cells_tour(tmp_path, capsys) -> None:
    out = tmp_path / "caltour.json"
    assert main(["plan-calibration", "-o", str(out), "--views", "4", "--quiet"]) == 0
    text = capsys.readouterr().out
    assert "robot time" in text and "predicted σ   hand-eye" in text
    cal = load_caltour(out)
    assert len(cal.tour.stops) == 4 and cal.design["criterion"] == "tcp"
    assert cal.prediction["hand_eye_sigma_m"] > 0 and cal.prediction["stops"] > 0
    assert cal.target["cols"] == 9 and cal.target["rows"] == 6


def test_cli_refuses_a_cell_without_a_target(tmp_path, capsys) -> None:
    data = yaml.safe_load(builtin_cell_path().read_text())
    del data["calibration_target"]
    cell = tmp_path / "cell.yaml"
    cell.write_text(yaml.safe_dump(data))
    out = tmp_path / "caltour.json"
    assert main(["plan-calibration", str(cell), "-o", str(out), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert "calibration_target: missing" in err and len(err.strip().splitlines()) == 1
    assert not out.exists()
