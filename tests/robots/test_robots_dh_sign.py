"""D-H rows of an arm whose joint 1 turns about -z (KUKA): joint_sign through IK and thermal."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from urdf_factory import KUKA_LIKE, write_urdf

from robots import Arm, dh_table, fk_dh, solve_ik
from robots.thermal import DriftTruth, ThermalModel, ThermalSpec, default_settings, solve_tcp
from robots.thermal.modelfile import load_model, save_model

Q = np.array([0.4, -0.35, 0.5, 0.6, 0.9, -0.3])


@pytest.fixture()
def kuka(tmp_path: Path) -> Arm:
    return Arm(write_urdf(tmp_path / "kuka_like.urdf", KUKA_LIKE))


def test_solve_ik_takes_a_signed_table(kuka: Arm) -> None:
    table = kuka.dh
    result = solve_ik(table, fk_dh(table, Q), kuka.lower, kuka.upper)
    assert result.ok and np.abs(result.solutions - Q).max(axis=1).min() < 1e-9
    assert len(result.solutions) == len(kuka.ik(kuka.fk(Q)).solutions)


def test_thermal_model_on_a_signed_table(kuka: Arm, tmp_path: Path) -> None:
    table = kuka.dh
    truth = DriftTruth(table, default_settings(per_joint_noise_K=0.0))
    k = truth.expansion_per_K
    spec = ThermalSpec.mapped(truth.settings.sensor_names, (20.0,) * 6)
    model = ThermalModel(table, spec, {f"k_link{i + 1}": float(k[i]) for i in range(6)})
    temps = np.full(6, 35.0)
    # at the reference temperature the model is the nominal arm, which is the URDF's
    assert np.abs(model.fk(Q, np.full(6, 20.0)) - kuka.fk(Q, "tool0")).max() < 1e-9
    # the damped least-squares command (Jacobian with the joint's own axis) converges
    warm = model.table_at(temps)
    goal = fk_dh(table, Q)
    res = solve_tcp(warm, goal, Q, np.eye(4))
    assert res.ok and np.abs(fk_dh(warm, res.q_rad) - goal)[:3, 3].max() < 1e-8
    path = tmp_path / "thermal.json"
    save_model(path, model)
    assert json.loads(path.read_text())["dh"]["joint_sign"] == [-1, 1, 1, 1, 1, 1]
    assert load_model(path).table == table


def test_abb_files_carry_no_joint_sign(tmp_path: Path) -> None:
    table = dh_table("abb_irb2600_20_165")
    model = ThermalModel(table, ThermalSpec.mapped(("amb",), (20.0,)), {})
    save_model(tmp_path / "t.json", model)
    assert "joint_sign" not in json.loads((tmp_path / "t.json").read_text())["dh"]
    assert load_model(tmp_path / "t.json").table == table
