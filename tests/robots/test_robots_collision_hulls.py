"""The tool-vs-wrist-mesh convex-hull pre-test keeps the exact answer (meshes made here)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from urdf_factory import ABB_LIKE, box_triangles, write_stl, write_urdf

import robots.collision as collision_module
from robots import Arm, Shape

HEAD = Shape("box", (0.1, 0.1, 0.1), np.eye(4), "head")
#: a lug 0.19 m off the flange axis: clear of the fork's hull at q = 0, inside a prong once J6
#: turns it a quarter turn
LUG = Shape(
    "sphere",
    (0.03,),
    np.array([[1, 0, 0, -0.19], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1.0]]),
    "lug",
)
#: the same lug on the other side, 5 mm off the block at q = 0 (closer than the tool's margin)
LUG_LOW = Shape(
    "sphere",
    (0.03,),
    np.array([[1, 0, 0, 0.19], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1.0]]),
    "lug",
)
QUARTER = np.array([0.0, 0.0, 0.0, 0.0, 0.0, np.pi / 2])


def _write_fork(path: Path) -> None:
    """Two prongs (OBJ) either side of link_4's axis, from 0.6 to 1.1 m along it: concave,
    so the tool between them is inside the mesh's convex hull but clear of the mesh."""
    lines, base = [], 0
    for y in (-0.2, 0.2):
        v, tris = box_triangles((0.5, 0.05, 0.1))
        lines += [f"v {x + 0.85} {yy + y} {z}" for x, yy, z in v]
        lines += [f"f {a + base + 1} {b + base + 1} {c + base + 1}" for a, b, c in tris]
        base += len(v)
    path.write_text("\n".join(lines) + "\n")


def _fork_arm(folder: Path, tool: list[Shape]) -> Arm:
    """An ABB-like arm with the fork as link_4, a small box as link_5, ``tool`` on tool0 and
    one block in reach; clearances 10 / 5 mm."""
    _write_fork(folder / "fork.obj")
    write_stl(folder / "wrist.stl", (0.05, 0.05, 0.05))
    sketch = ABB_LIKE.with_(mesh_uris={"link_4": "fork.obj", "link_5": "wrist.stl"})
    arm = Arm(write_urdf(folder / "arm.urdf", sketch))
    arm.set_tool(np.eye(4), tool)
    T = np.eye(4)
    T[:3, 3] = [1.3, 0.0, 0.9]
    arm.add_obstacles([Shape("box", (0.3, 0.3, 0.3), T, "block")])
    arm.set_clearance(0.010, 0.005)
    return arm


def _branch(cm: collision_module.CollisionModel, verdict: bool) -> str:
    """Which way the last ``in_collision`` call decided (read from the fast pass's callback)."""
    k = cm._first_hit.collisionPairIndex
    if k >= len(cm.geom_model.collisionPairs):  # no contact in the fast pass
        assert not verdict
        return "hull pass free"
    if k not in cm._mesh_pair_of:
        return "real pair hit"
    if cm._fast_data.collisionResults[cm._mesh_pair_of[k]].isCollision():
        return "hull hit, its mesh hit"
    return "hull hit, its mesh clear: every pair"


def _agrees_on_random(arm: Arm, n: int) -> set[str]:
    cm, rng = arm.collision, np.random.default_rng(5)
    verdicts, branches = [], set()
    for _ in range(n):
        q = rng.uniform(arm.lower, arm.upper)
        verdicts.append(arm.in_collision(q))
        branches.add(_branch(cm, verdicts[-1]))
        assert verdicts[-1] == cm.in_collision_exhaustive(q)
    assert any(verdicts) and not all(verdicts)
    return branches


@pytest.mark.parametrize("naive_max", [120, 0], ids=["naive", "sweep-and-prune"])
def test_hull_pretest_agrees_with_every_pair_and_falls_back_inside_the_hull(
    tmp_path: Path, naive_max: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(collision_module, "NAIVE_MAX_GEOMETRIES", naive_max)
    arm = _fork_arm(tmp_path, [HEAD])
    cm = arm.collision
    assert len(cm.hull_pairs) == 2 and len(cm.mesh_pairs) == 2  # head vs link_4, link_5
    q0 = np.zeros(6)
    # at q = 0 the head sits between the prongs: the hull pass hits, the exact pairs do not
    assert pin.computeCollisions(cm.model, cm.data, cm._fast_broadphase, q0, True)
    assert not arm.in_collision(q0) and not cm.in_collision_exhaustive(q0)
    assert _branch(cm, False) == "hull hit, its mesh clear: every pair"
    assert "real pair hit" in _agrees_on_random(arm, 400)
    # the pre-test's pairs are not reported: names and distances are the exact pairs'
    assert all("#hull" not in a + b for a, b in cm.colliding_pairs(q0))
    assert "#hull" not in "".join(cm.clearance(q0)[1])


@pytest.mark.parametrize("naive_max", [120, 0], ids=["naive", "sweep-and-prune"])
def test_a_hull_hit_is_decided_by_its_mesh_pair(
    tmp_path: Path, naive_max: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(collision_module, "NAIVE_MAX_GEOMETRIES", naive_max)
    arm = _fork_arm(tmp_path, [LUG])
    cm = arm.collision
    assert not arm.in_collision(np.zeros(6)) and _branch(cm, False) == "hull pass free"
    assert arm.in_collision(QUARTER) and cm.in_collision_exhaustive(QUARTER)
    assert _branch(cm, True) == "hull hit, its mesh hit"
    assert arm.colliding_pairs(QUARTER) == [("link_4_0", "tool_0:lug")]
    assert {"hull pass free", "real pair hit"} <= _agrees_on_random(arm, 200)


def test_a_hull_hit_with_its_mesh_clear_still_finds_a_later_contact(tmp_path: Path) -> None:
    arm = _fork_arm(tmp_path, [HEAD, LUG_LOW])
    q0 = np.zeros(6)
    # the naive broad phase visits pairs in geometry order, head before lug: the head inside
    # the fork's hull stops the fast pass, its mesh pair is clear, the lug against the block
    # (after that hull pair) decides
    assert "Naive" in type(arm.collision._fast_broadphase).__name__
    assert arm.in_collision(q0) and arm.collision.in_collision_exhaustive(q0)
    assert _branch(arm.collision, True) == "hull hit, its mesh clear: every pair"
    assert arm.colliding_pairs(q0) == [("tool_1:lug", "obstacle_0:block")]
