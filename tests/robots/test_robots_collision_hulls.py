"""The tool-vs-wrist-mesh convex-hull pre-test keeps the exact answer (meshes made here)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
from urdf_factory import ABB_LIKE, box_triangles, write_stl, write_urdf

from robots import Arm, Shape


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


def test_hull_pretest_agrees_with_every_pair_and_falls_back_inside_the_hull(
    tmp_path: Path,
) -> None:
    _write_fork(tmp_path / "fork.obj")
    write_stl(tmp_path / "wrist.stl", (0.05, 0.05, 0.05))
    sketch = ABB_LIKE.with_(mesh_uris={"link_4": "fork.obj", "link_5": "wrist.stl"})
    arm = Arm(write_urdf(tmp_path / "arm.urdf", sketch))
    arm.set_tool(np.eye(4), [Shape("box", (0.1, 0.1, 0.1), np.eye(4), "head")])
    T = np.eye(4)
    T[:3, 3] = [1.3, 0.0, 0.9]
    arm.add_obstacles([Shape("box", (0.3, 0.3, 0.3), T, "block")])
    arm.set_clearance(0.010, 0.005)
    cm = arm.collision
    assert len(cm.hull_pairs) == 2 and len(cm.mesh_pairs) == 2  # head vs link_4, link_5
    q0 = np.zeros(6)
    # at q = 0 the head sits between the prongs: the hull pass hits, the exact pairs do not
    assert pin.computeCollisions(cm.model, cm.data, cm._fast_broadphase, q0, True)
    assert not arm.in_collision(q0) and not cm.in_collision_exhaustive(q0)
    rng = np.random.default_rng(5)
    verdicts = []
    for _ in range(400):
        q = rng.uniform(arm.lower, arm.upper)
        verdicts.append(arm.in_collision(q))
        assert verdicts[-1] == cm.in_collision_exhaustive(q)
    assert any(verdicts) and not all(verdicts)
    # the pre-test's pairs are not reported: names and distances are the exact pairs'
    assert all("#hull" not in a + b for a, b in cm.colliding_pairs(q0))
    assert "#hull" not in "".join(cm.clearance(q0)[1])
