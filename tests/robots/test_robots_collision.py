"""Collision checks on hand-built cases, cross-checked against distance queries."""

from __future__ import annotations

import numpy as np
import pytest

import robots.collision as collision_module
from robots import Arm, Shape, ShapeError
from robots.transforms import make_transform, pose_to_matrix

Q_FREE = np.array([0.0, 0.0, 0.0, 0.0, 0.5, 0.0])


def _tool_arm() -> Arm:
    arm = Arm()
    arm.set_tool(
        pose_to_matrix([0, 0, 0.15]),
        [Shape("box", (0.24, 0.12, 0.10), pose_to_matrix([0, 0, 0.08]), "head")],
    )
    return arm


def test_free_arm_is_free_and_has_clearance() -> None:
    arm = _tool_arm()
    assert not arm.in_collision(Q_FREE)
    assert arm.clearance(Q_FREE) > 0.0


def test_obstacle_at_the_tcp_collides_with_the_tool() -> None:
    arm = _tool_arm()
    tcp = arm.fk(Q_FREE)
    arm.add_obstacles([Shape("sphere", (0.05,), make_transform(t=tcp[:3, 3]), "ball")])
    assert arm.in_collision(Q_FREE)
    assert any("head" in a or "head" in b for a, b in arm.colliding_pairs(Q_FREE))
    assert arm.clearance(Q_FREE) < 0.0


def test_obstacle_far_away_is_free() -> None:
    arm = _tool_arm()
    arm.add_obstacles([Shape("box", (0.2, 0.2, 0.2), make_transform(t=[-2.0, 2.0, 0.5]), "crate")])
    assert not arm.in_collision(Q_FREE)


def test_obstacles_follow_the_base_pose() -> None:
    T_cell_base = make_transform(t=[1.0, 0.0, 0.0])
    arm = Arm(T_cell_base=T_cell_base)
    wrist = arm.fk(Q_FREE, "flange")[:3, 3]
    arm.add_obstacles([Shape("sphere", (0.03,), make_transform(t=wrist), "probe")])
    assert arm.in_collision(Q_FREE)


def test_self_collision_forearm_into_base() -> None:
    arm = Arm()
    # J2 forward and J3 folded down drives the wrist into the robot's own base
    q = np.array([0.0, 1.6, 1.2, 0.0, 0.0, 0.0])
    assert arm.in_collision(q)
    pairs = arm.colliding_pairs(q)
    assert all("obstacle" not in a and "obstacle" not in b for a, b in pairs)


def test_adjacent_links_are_not_checked() -> None:
    arm = Arm()
    names = [g.name for g in arm.collision.geom_model.geometryObjects]
    checked = {
        (names[p.first].split("_0")[0], names[p.second].split("_0")[0])
        for p in arm.collision.geom_model.collisionPairs
    }
    for a, b in (("base_link", "link_1"), ("link_2", "link_3"), ("link_5", "link_6")):
        assert (a, b) not in checked and (b, a) not in checked
    assert ("link_2", "link_4") in checked


def test_penetrating_cylinders_are_caught() -> None:
    # coal 3.0 with contacts off reports these overlaps as free; the checker must not
    arm = Arm()
    arm.set_tool(
        pose_to_matrix([0, 0, 0.1]),
        [Shape("cylinder", (0.03, 0.2), pose_to_matrix([0, 0, 0.1]), "rod")],
    )
    tcp = arm.fk(Q_FREE)
    for angle in np.linspace(0.1, 1.5, 8):
        T = tcp @ pose_to_matrix([0.0, 0.0, -0.05], [angle, 0.0, 0.0])
        arm.obstacles = []
        arm.add_obstacles([Shape("cylinder", (0.02, 0.4), T, "bar")])
        assert arm.in_collision(Q_FREE), angle
        assert arm.clearance(Q_FREE) < 0.0


def test_deep_cylinder_overlap_missed_by_plain_gjk_is_caught() -> None:
    # a pair found by search that coal 3.0 reports free when contacts are off (depth 0.116 m)
    from scipy.spatial.transform import Rotation

    arm = Arm()
    arm.set_tool(
        np.eye(4), [Shape("cylinder", (0.08546677234978937, 0.5659134946168579), np.eye(4), "c1")]
    )
    T_rel = make_transform(
        Rotation.from_rotvec(
            [1.1296238399332283, -0.14014625557604912, -0.08972149034161887]
        ).as_matrix(),
        [-0.07498355072455637, 0.0937719165035038, 0.114012439535989],
    )
    T_cell_tool0 = arm.fk(Q_FREE, "tool0")
    arm.add_obstacles(
        [Shape("cylinder", (0.12016680467225231, 0.8696182412435091), T_cell_tool0 @ T_rel, "c2")]
    )
    assert arm.clearance(Q_FREE) < -0.1
    assert arm.in_collision(Q_FREE)
    assert arm.collision.in_collision_exhaustive(Q_FREE)


@pytest.mark.parametrize("naive_max", [120, 0], ids=["naive", "sweep-and-prune"])
def test_collision_agrees_with_exhaustive_check_and_distance(
    naive_max: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(collision_module, "NAIVE_MAX_GEOMETRIES", naive_max)
    arm = _tool_arm()
    rng = np.random.default_rng(2)
    for i in range(30):
        centre = rng.uniform([0.6, -0.8, 0.2], [1.4, 0.8, 1.4])
        arm.add_obstacles(
            [Shape("cylinder", (0.02, 0.5), pose_to_matrix(centre, rng.uniform(-3, 3, 3)), f"t{i}")]
        )
    n_hit = 0
    for q in rng.uniform(arm.lower, arm.upper, (400, 6)):
        hit = arm.in_collision(q)
        n_hit += hit
        assert hit == arm.collision.in_collision_exhaustive(q)
        distance = arm.clearance(q)
        if abs(distance) > 1e-6:
            assert hit == (distance < 0.0)
    assert 0 < n_hit < 400
    kind = "Naive" if naive_max else "SSaP"
    assert kind in type(arm.collision.broadphase).__name__


def test_bad_shapes_are_refused() -> None:
    with pytest.raises(ShapeError, match="cone"):
        Shape("cone", (1.0,))
    with pytest.raises(ShapeError, match="positive"):
        Shape("sphere", (-0.1,))
    with pytest.raises(ShapeError, match="takes 2"):
        Shape("cylinder", (0.1,))
