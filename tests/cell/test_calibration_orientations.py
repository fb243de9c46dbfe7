"""The calibration tour's summary names distinct orientations instead of a smallest rotation
between views that is 0 whenever two views look from one direction."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from cell.calibration.plan import orientation_figures
from cell.commands.plan_calibration_cmd import orientation_line


def _R(*rotvecs_deg) -> np.ndarray:
    return Rotation.from_rotvec(np.radians(rotvecs_deg)).as_matrix()


def test_views_from_one_direction_share_an_orientation() -> None:
    R = _R([0, 0, 0], [0, 0, 0.3], [30, 0, 0], [0, 45, 0], [30.2, 0, 0])
    k, gap = orientation_figures(R)
    assert k == 3 and np.degrees(gap) == pytest.approx(30.0)
    assert orientation_figures(_R([0, 0, 0], [0, 0, 0]))[0] == 1
    assert orientation_figures(_R([0, 0, 0])) == (1, None)
    assert orientation_line(
        {"orientations": 1, "min_rotation_between_orientations_rad": None}, 3
    ) == ("orientations  1 distinct (the other 2 repeat one from another distance or offset)")


def test_the_summary_line() -> None:
    d = {"orientations": 3, "min_rotation_between_orientations_rad": np.radians(30.0)}
    assert orientation_line(d, 5) == (
        "orientations  3 distinct, at least 30.0 deg apart (the other 2 repeat one from "
        "another distance or offset)"
    )
    d = {"orientations": 5, "min_rotation_between_orientations_rad": np.radians(21.04)}
    assert orientation_line(d, 5) == "orientations  5 distinct, at least 21.0 deg apart"


@pytest.mark.slow  # 8 s of planning; the two tests above hold the figures and the line
def test_plan_calibration_prints_the_orientations(tmp_path, capsys) -> None:
    from cell.cli import main
    from planner.calibration import load_caltour

    out = tmp_path / "caltour.json"
    args = ["plan-calibration", "-o", str(out), "--views", "5", "--criterion", "geometric"]
    assert main([*args, "--quiet"]) == 0
    lines = capsys.readouterr().out.splitlines()
    d = load_caltour(out).design
    assert d["orientations"] == 5  # the geometric design keeps views >= 20 deg apart
    assert d["min_rotation_between_orientations_rad"] == pytest.approx(d["min_rotation_rad"])
    want = f"orientations  5 distinct, at least {np.degrees(d['min_rotation_rad']):.1f} deg apart"
    assert want in lines and not any("smallest rotation" in s for s in lines)
