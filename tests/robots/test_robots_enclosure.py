"""The built-in arms' primitives enclose the ROS-Industrial collision meshes of the same arms.

``data/rosi_link_points.json`` holds, per model and link, points measured on the ROS-I
collision mesh (``benchmarks/fit_link_shapes.py``): its extreme points along 26 directions
and its 8 points closest to leaving our primitives, in the link frame (m). No mesh is kept.
"""

from __future__ import annotations

import json
from pathlib import Path

import coal
import numpy as np
import pytest

from robots import Arm
from robots.models import MODELS

POINTS = json.loads((Path(__file__).parent / "data" / "rosi_link_points.json").read_text())


def _inside(geom: coal.CollisionGeometry, p: np.ndarray) -> np.ndarray:
    """Whether points ``p`` (N, 3, primitive frame) lie inside the primitive."""
    if isinstance(geom, coal.Box):
        return np.all(np.abs(p) <= geom.halfSide, axis=1)
    if isinstance(geom, coal.Cylinder):
        return (np.hypot(p[:, 0], p[:, 1]) <= geom.radius) & (np.abs(p[:, 2]) <= geom.halfLength)
    if isinstance(geom, coal.Sphere):
        return np.linalg.norm(p, axis=1) <= geom.radius
    raise TypeError(type(geom).__name__)


def _link_prims(arm: Arm, link: str) -> list[tuple[coal.CollisionGeometry, np.ndarray]]:
    fid = arm.model.getFrameId(link)
    return [
        (g.geometry, g.placement.homogeneous)
        for g in arm._robot_geoms.geometryObjects
        if g.parentFrame == fid
    ]


@pytest.mark.parametrize("name", sorted(MODELS))
def test_every_measured_mesh_point_is_inside_the_links_primitives(name: str) -> None:
    arm = Arm(name)
    for link, pts in POINTS[name].items():
        p = np.asarray(pts)
        inside = np.zeros(len(p), bool)
        for geom, T in _link_prims(arm, link):
            inside |= _inside(geom, (p - T[:3, 3]) @ T[:3, :3])
        assert inside.all(), f"{name} {link}: {p[~inside].tolist()} outside"


def test_a_shrunk_primitive_lets_measured_points_out() -> None:
    # the stored points are tight: 2 mm less on the 2600's link_4 box leaves points outside
    arm = Arm("abb_irb2600_20_165")
    prims = _link_prims(arm, "link_4")
    k = next(i for i, (g, _) in enumerate(prims) if isinstance(g, coal.Box))
    geom, T = prims[k]
    smaller = coal.Box(*(2 * geom.halfSide - 0.004))
    p = np.asarray(POINTS["abb_irb2600_20_165"]["link_4"])
    others = prims[:k] + prims[k + 1 :]
    inside = _inside(smaller, (p - T[:3, 3]) @ T[:3, :3])
    for g, Tg in others:
        inside |= _inside(g, (p - Tg[:3, 3]) @ Tg[:3, :3])
    assert not inside.all()
