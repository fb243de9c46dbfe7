"""Application per pose: the measurement transform and the command on known drifts."""

from __future__ import annotations

import numpy as np
import pytest

from robots.dh import fk_dh
from robots.thermal import (
    CommandOptions,
    DriftTruth,
    T_part_camera,
    ThermalModel,
    ThermalSpec,
    camera_to_part,
    command,
    default_settings,
    solve_tcp,
)
from robots.transforms import invert, pose_to_matrix, rotation_angle

Q = np.array([0.4, 0.35, -0.25, 0.6, 0.9, -0.3])
T_WARM = 5400.0


@pytest.fixture()
def truth(table):
    return DriftTruth(table, default_settings(per_joint_noise_K=0.0))


@pytest.fixture()
def model(table, truth, T_cell_base, T_tool0_tcp):
    """The model with the true coefficients (the drift is known exactly)."""
    k = truth.expansion_per_K
    spec = ThermalSpec.mapped(truth.settings.sensor_names, (20.0,) * 6)
    coeffs = {f"k_link{i + 1}": float(k[i]) for i in range(6)}
    return ThermalModel(table, spec, coeffs, T_cell_base=T_cell_base, T_tool0_tcp=T_tool0_tcp)


def test_compensated_fk_equals_the_drifted_truth(model, truth):
    temps = truth.sensor_readings(T_WARM)
    assert np.allclose(model.fk(Q, temps), truth.T_base_tool0(Q, T_WARM), atol=1e-14)


def test_measurement_transform_brings_a_camera_point_into_the_part_frame(
    model, truth, T_cell_base, T_tool0_tcp
):
    T_cell_part = pose_to_matrix([1.2, 0.3, 0.4], rpy=[0.1, -0.2, 0.5])
    T_tcp_cam = pose_to_matrix([0.03, 0.0, -0.35], rpy=[0.0, 0.0, np.pi / 2])
    hole_part = np.array([[0.01, 0.02, 0.03], [-0.05, 0.0, 0.01]])
    axis_part = np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0]])
    T_cell_cam = T_cell_base @ truth.T_base_tool0(Q, T_WARM) @ T_tool0_tcp @ T_tcp_cam
    T_cam_part_true = invert(T_cell_cam) @ T_cell_part
    hole_cam = hole_part @ T_cam_part_true[:3, :3].T + T_cam_part_true[:3, 3]
    axis_cam = axis_part @ T_cam_part_true[:3, :3].T
    temps = truth.sensor_readings(T_WARM)
    T = T_part_camera(model, Q, temps, T_cell_part, T_tcp_cam)
    p, axes = camera_to_part(T, hole_cam, axis_cam)
    assert np.allclose(p, hole_part, atol=1e-12)
    assert np.allclose(axes, axis_part, atol=1e-12)
    cold = T_part_camera(model, Q, np.full(6, 20.0), T_cell_part, T_tcp_cam)
    p_cold, _ = camera_to_part(cold, hole_cam)
    assert np.linalg.norm(p_cold - hole_part, axis=1).min() > 5e-5  # uncompensated: tenths of a mm


def test_command_puts_the_warm_tcp_on_the_nominal_pose(model, truth, table, T_tool0_tcp):
    temps = truth.sensor_readings(T_WARM)
    result = command(model, Q, temps)
    assert result.ok and result.iterations <= 6
    T_goal = fk_dh(table, Q) @ T_tool0_tcp
    T_reached = truth.T_base_tool0(result.q_rad, T_WARM) @ T_tool0_tcp
    assert np.linalg.norm(T_reached[:3, 3] - T_goal[:3, 3]) < 1e-9
    assert rotation_angle(T_reached[:3, :3], T_goal[:3, :3]) < 1e-9
    T_uncompensated = truth.T_base_tool0(Q, T_WARM) @ T_tool0_tcp
    assert np.linalg.norm(T_uncompensated[:3, 3] - T_goal[:3, 3]) > 1e-4
    assert 1e-6 < np.max(np.abs(result.q_rad - Q)) < 1e-2


def test_command_at_reference_temperature_returns_the_nominal_joints(model):
    result = command(model, Q, np.full(6, 20.0))
    assert result.ok and result.iterations == 0
    assert np.array_equal(result.q_rad, Q)


def test_solve_reports_unreachable_goals(table, T_tool0_tcp):
    far = pose_to_matrix([5.0, 0.0, 1.0])
    result = solve_tcp(table, far, Q, T_tool0_tcp, CommandOptions(max_iterations=15))
    assert result.status == "not converged"
    assert result.position_error_m > 1.0
