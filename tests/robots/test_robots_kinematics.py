"""Forward kinematics of the shipped URDFs against the D-H tables and the reference figures."""

from __future__ import annotations

import numpy as np
import pytest

from robots import MODELS, Arm, dh_table, fk_dh
from robots.arm_shapes import LINK_PRIMITIVES
from robots.urdf_writer import URDF_DIR, urdf_text

NAMES = sorted(MODELS)

# flange position at q = 0 from docs/abb_kinematics.md (m)
FLANGE_AT_ZERO = {
    "abb_irb1600_10_145": (0.815, 0.0, 1.1865),
    "abb_irb2600_20_165": (1.030, 0.0, 1.260),
    "abb_irb4600_60_205": (1.270, 0.0, 1.570),
}


@pytest.mark.parametrize("name", NAMES)
def test_urdf_matches_dh_at_random_configurations(name: str) -> None:
    arm = Arm(name)
    table = dh_table(name)
    rng = np.random.default_rng(7)
    for q in rng.uniform(arm.lower, arm.upper, (200, 6)):
        T_pin = arm.fk(q, "tool0")
        T_dh = fk_dh(table, q)
        assert np.abs(T_pin[:3, 3] - T_dh[:3, 3]).max() < 1e-9
        assert np.abs(T_pin[:3, :3] - T_dh[:3, :3]).max() < 1e-9


@pytest.mark.parametrize("name", NAMES)
def test_reference_reach_and_flange_at_zero(name: str) -> None:
    spec = MODELS[name]
    reach = spec.a1 + spec.a2 + np.hypot(spec.d4, spec.a3)
    assert reach == pytest.approx(spec.reach_m, abs=0.0035)
    arm = Arm(name)
    assert np.allclose(arm.fk(np.zeros(6), "flange")[:3, 3], FLANGE_AT_ZERO[name], atol=1e-12)
    # tool0 is link_6 turned +90 deg about y: its z axis is the flange normal (+x at q = 0)
    assert np.allclose(arm.fk(np.zeros(6), "tool0")[:3, 2], [1.0, 0.0, 0.0], atol=1e-12)
    # the wrist centre stays within the annulus the upper arm and forearm can span about J2
    rng = np.random.default_rng(1)
    q = rng.uniform(arm.lower, arm.upper, (2000, 6))
    T = fk_dh(dh_table(name), q)
    wrist = T[:, :3, 3] - spec.d6 * T[:, :3, 2]
    shoulder = np.column_stack(
        (spec.a1 * np.cos(q[:, 0]), spec.a1 * np.sin(q[:, 0]), np.full(len(q), spec.d1))
    )
    span = np.linalg.norm(wrist - shoulder, axis=1)
    forearm = np.hypot(spec.d4, spec.a3)
    assert span.max() <= spec.a2 + forearm + 1e-9
    assert span.min() >= abs(spec.a2 - forearm) - 1e-9
    assert span.max() > 0.95 * (spec.a2 + forearm)  # the sample reaches near full stretch


@pytest.mark.parametrize("name", NAMES)
def test_shipped_urdf_is_the_writers_output(name: str) -> None:
    assert (URDF_DIR / f"{name}.urdf").read_text() == urdf_text(MODELS[name])


@pytest.mark.parametrize("name", NAMES)
def test_collision_model_keeps_every_link_shape(name: str) -> None:
    # a <capsule> in a URDF makes Pinocchio drop the link's collision elements silently
    arm = Arm(name)
    bodies = [info.body for info in arm.collision.infos]
    for link in ("base_link", "link_1", "link_2", "link_3", "link_4", "link_5", "link_6"):
        assert link in bodies
    for link in ("base_link", "link_1", "link_2", "link_3", "link_4", "link_5", "link_6"):
        expected = sum(row[0] == link for row in LINK_PRIMITIVES[name])
        assert bodies.count(link) == expected


def test_tcp_frame_follows_the_tool_and_base() -> None:
    T_cell_base = np.eye(4)
    T_cell_base[:3, 3] = [0.5, -0.2, 0.3]
    arm = Arm(T_cell_base=T_cell_base)
    T_tool0_tcp = np.eye(4)
    T_tool0_tcp[:3, 3] = [0.0, 0.0, 0.15]
    arm.set_tool(T_tool0_tcp)
    q = np.array([0.3, 0.1, -0.2, 0.5, 0.7, -0.4])
    T_tool0 = arm.fk(q, "tool0")
    T_tcp = arm.fk(q, "tcp")
    assert np.allclose(T_tcp[:3, 3], T_tool0[:3, 3] + 0.15 * T_tool0[:3, 2])
    assert np.allclose(T_tool0, T_cell_base @ fk_dh(arm.dh, q))
    assert np.allclose(arm.fk_dh(q), T_tcp)
    assert np.allclose(arm.fk_dh(q, "flange"), arm.fk(q, "flange"))
    with pytest.raises(ValueError, match="frame"):
        arm.fk_dh(q, "TCP")
