"""Viewing poses of the reference targets."""

from __future__ import annotations

import numpy as np
import pytest

from robots.dh import fk_dh
from robots.models import MODELS
from robots.thermal import ThermalDataError
from robots.thermal.plan import ViewOptions, view_plan, view_pose
from robots.transforms import invert

SPEC = MODELS["abb_irb2600_20_165"]


def test_view_pose_puts_the_target_on_the_camera_axis():
    target = np.array([1.0, 0.4, 0.3])
    for tilt, az, roll in [(0.0, 0.0, 0.0), (0.5, 1.0, 0.3), (0.45, 2.2, -0.8)]:
        T = view_pose(target, [0, 0, 1], tilt, az, roll, 0.25)
        p_tcp = invert(T) @ np.append(target, 1.0)
        assert np.allclose(p_tcp[:3], [0.0, 0.0, 0.25], atol=1e-12)
        assert np.arccos(-T[2, 2]) == pytest.approx(tilt, abs=1e-9)


def test_view_plan_reaches_every_view(table, T_cell_base, T_tool0_tcp):
    targets = {"A": ((1.0, -0.3, 0.3), (0, 0, 1)), "B": ((0.8, 0.6, 0.5), (0, 0, 1))}
    plan = view_plan(table, SPEC.lower_rad, SPEC.upper_rad, T_cell_base, T_tool0_tcp, targets, 0.2)
    assert not plan.skipped and [t for t, _ in plan.poses] == ["A"] * 3 + ["B"] * 3
    for tid, q in plan.poses:
        T_cell_tcp = T_cell_base @ fk_dh(table, q) @ T_tool0_tcp
        p_tcp = invert(T_cell_tcp) @ np.append(targets[tid][0], 1.0)
        assert np.allclose(p_tcp[:3], [0.0, 0.0, 0.2], atol=1e-9)
    qs = np.array([q for _, q in plan.poses[:3]])
    assert np.ptp(qs[:, 1:3], axis=0).max() > 0.05  # the views differ in the arm joints too


def test_unreachable_and_vetoed_views(table, T_cell_base, T_tool0_tcp):
    lo, hi = SPEC.lower_rad, SPEC.upper_rad
    far = {"far": ((4.0, 0.0, 0.3), (0, 0, 1))}
    with pytest.raises(ThermalDataError, match="out of reach"):
        view_plan(table, lo, hi, T_cell_base, T_tool0_tcp, far, 0.2)
    targets = {"A": ((1.0, -0.6, 0.3), (0, 0, 1)), "B": ((0.6, 1.0, 0.3), (0, 0, 1))}
    T_base_cell = invert(T_cell_base)
    pB = T_base_cell @ np.array([0.6, 1.0, 0.3, 1.0])
    j1_B = np.arctan2(pB[1], pB[0])
    plan = view_plan(
        table,
        lo,
        hi,
        T_cell_base,
        T_tool0_tcp,
        targets,
        0.2,
        ViewOptions((0.0, 0.3), (0.0, 1.0), (0.0, 0.0)),
        accept=lambda q: abs(q[0] - j1_B) < 0.5,
    )
    assert [t for t, _ in plan.poses] == ["B", "B"]
    assert [(t, k) for t, k, _ in plan.skipped] == [("A", 0), ("A", 1)]
    assert all("vetoed" in reason for _, _, reason in plan.skipped)
