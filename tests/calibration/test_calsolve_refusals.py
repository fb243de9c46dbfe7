"""Data sets that cannot determine the hand-eye are refused with one line saying why."""

from __future__ import annotations

import numpy as np
import pytest
from calsolve_fixtures import seen_views

from cell.calibration.errors import CalibrationDataError, DegenerateCalibrationError
from cell.calibration.estimate import (
    CalibrationObservations,
    CalibrationView,
    example_truth,
    reference_joints,
    simulate,
    solve_calibration,
)
from robots.dh_models import dh_table


def _views(tr, Q, seen=None):
    """Views at joints Q with placeholder corners (the checks run before any corner is used)."""
    M = len(tr.target.object_points())
    seen = np.ones(len(Q), bool) if seen is None else seen
    return CalibrationObservations(
        tuple(
            CalibrationView(f"view{i}", np.zeros((M, 2)) if s else None, np.zeros((M, 2)), q)
            for i, (q, s) in enumerate(zip(Q, seen, strict=True))
        ),
        tr.target,
        tr.cameras,
        "poses.csv",
    )


def test_too_few_views() -> None:
    tr = example_truth(0)
    Q = seen_views(tr, 2, seed=1)
    with pytest.raises(DegenerateCalibrationError, match=r"2 view\(s\) in poses.csv; at least 3"):
        solve_calibration(_views(tr, Q), tr.dh)


@pytest.mark.parametrize("joint", [4, 5])
def test_rotations_about_one_joint_axis_are_parallel(joint: int) -> None:
    tr = example_truth(0)
    Q = np.repeat(reference_joints(tr)[None], 6, axis=0)
    Q[:, joint] += np.linspace(-0.4, 0.4, 6)
    with pytest.raises(DegenerateCalibrationError, match=r"\(near-\)parallel axes") as exc:
        solve_calibration(_views(tr, Q), tr.dh)
    assert "\n" not in str(exc.value)


def test_views_that_do_not_turn() -> None:
    tr = example_truth(0)
    Q = np.repeat(reference_joints(tr)[None], 5, axis=0)
    with pytest.raises(DegenerateCalibrationError, match=r"turn by at most 0\.00 deg"):
        solve_calibration(_views(tr, Q), tr.dh)


def test_the_target_seen_in_too_few_views() -> None:
    tr = example_truth(0)
    Q = seen_views(tr, 6, seed=1)
    seen = np.array([True, True, False, False, False, False])
    with pytest.raises(DegenerateCalibrationError, match="seen in 2 of 6 left images") as exc:
        solve_calibration(_views(tr, Q, seen), tr.dh)
    assert "view2" in str(exc.value)


def test_joints_of_another_arm_are_refused_as_implausible() -> None:
    tr = example_truth(0, model="abb_irb1600_10_145")
    obs = simulate(tr, seen_views(tr, 12, seed=2), 0.1)
    with pytest.raises(CalibrationDataError, match="plausible: within") as exc:
        solve_calibration(obs, dh_table("abb_irb2600_20_165"))
    assert "cell's robot model" in str(exc.value)


def test_joints_without_a_table_and_mixed_views_are_refused() -> None:
    tr = example_truth(0)
    Q = seen_views(tr, 4, seed=1)
    with pytest.raises(DegenerateCalibrationError, match="no nominal D-H table"):
        solve_calibration(_views(tr, Q))
    views = list(_views(tr, Q).views)
    views[1] = CalibrationView("odd", views[1].corners_left_px, None, None, np.eye(4))
    with pytest.raises(CalibrationDataError, match="some views give joints"):
        CalibrationObservations(tuple(views), tr.target, tr.cameras, "poses.csv")
