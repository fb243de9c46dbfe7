"""holecell plan-calibration: the calibration tour of a cell (cell.calibration_plan)."""

from __future__ import annotations

import numpy as np
import pytest

from cell.calibration_plan.plan import CalibrationPlanOptions, joint_range, plan_calibration
from cell.calibration_plan.target import TargetGeometry
from cell.config import load_builtin_cell
from cell.errors import CellError
from cell.run.camera import cell_stereo
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


def test_geometric_plan_of_a_placed_target(cell, tmp_path) -> None:
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


def test_more_views_than_feasible_are_refused(cell) -> None:
    o = CalibrationPlanOptions(views=5000, criterion="geometric")
    with pytest.raises(CellError, match="feasible view"):
        plan_calibration(cell, TARGET, cell_stereo(cell), np.array([cell.home_q()]), o)


def test_bad_options_are_refused() -> None:
    with pytest.raises(CellError, match="criterion"):
        CalibrationPlanOptions(criterion="e")
    with pytest.raises(CellError, match="corner_sigma_px"):
        CalibrationPlanOptions(corner_sigma_px=0.0)
