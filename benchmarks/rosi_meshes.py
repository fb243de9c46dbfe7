"""The ROS-Industrial collision meshes of our three ABB arms, for benchmarks and evidence scripts.

``ros-industrial/abb_experimental`` (Apache-2.0) ships STL collision meshes per link
(``<package>/meshes/<model>/collision/<link>.stl``) whose URDF collision origins are all identity
and whose joint origins equal ours (``rosi_enclosure.py`` checks the frames), so each mesh is in
our link frame as it is. Nothing here is committed from that repository: the scripts take the
path of a checkout.

Our IRB 1600-10/1.45 uses ROS-I's ``irb1600_8_145`` (same arm, same lengths); our
IRB 2600-20/1.65 uses ``irb2600_12_165`` (same arm, other payload); IRB 4600-60/2.05 is
``irb4600_60_205``.
"""

from __future__ import annotations

import sys
from pathlib import Path

import coal
import numpy as np
import trimesh
from numpy.typing import NDArray

Array = NDArray[np.float64]

LINKS = ("base_link", "link_1", "link_2", "link_3", "link_4", "link_5", "link_6")


def _mesh_table(package: str, common: str, own: str, own_links: tuple[str, ...]) -> dict[str, str]:
    return {
        link: f"{package}/meshes/{own if link in own_links else common}/collision/{link}.stl"
        for link in LINKS
    }


#: our model name -> (ROS-I xacro name, {link: mesh path relative to the checkout})
ROSI_MODELS: dict[str, tuple[str, dict[str, str]]] = {
    "abb_irb1600_10_145": (
        "irb1600_8_145",
        _mesh_table("abb_irb1600_support", "irb1600", "irb1600_8_145", ("link_2",)),
    ),
    "abb_irb2600_20_165": (
        "irb2600_12_165",
        _mesh_table("abb_irb2600_support", "irb2600_12_165", "irb2600_12_165", ()),
    ),
    "abb_irb4600_60_205": (
        "irb4600_60_205",
        _mesh_table("abb_irb4600_support", "irb4600", "irb4600_60_205", LINKS[2:]),
    ),
}


def frame_differences(root: Path, model: str) -> tuple[float, float]:
    """Largest difference between ROS-I's and our joint origins (m, rad) and largest offset
    of a ROS-I collision origin (m, rad), read from the xacro macro (plain numbers there)."""
    import xml.etree.ElementTree as ET

    from robots.models import JOINT_AXES, MODELS

    name, table = ROSI_MODELS[model]
    package = next(iter(table.values())).split("/")[0]
    tree = ET.parse(root / package / "urdf" / f"{name}_macro.xacro")
    joints = {j.get("name", "").replace("${prefix}", ""): j for j in tree.iter("joint")}
    spec = MODELS[model]
    axis_vec = {"x": (1, 0, 0), "y": (0, 1, 0), "z": (0, 0, 1)}
    joint_diff = 0.0
    for i in range(6):
        j = joints[f"joint_{i + 1}"]
        origin = j.find("origin")
        xyz = np.array([float(v) for v in origin.get("xyz", "0 0 0").split()])
        rpy = np.array([float(v) for v in origin.get("rpy", "0 0 0").split()])
        axis = np.array([float(v) for v in j.find("axis").get("xyz").split()])
        joint_diff = max(
            joint_diff,
            float(np.abs(xyz - spec.joint_origins_m[i]).max()),
            float(np.abs(rpy).max()),
            float(np.abs(axis - axis_vec[JOINT_AXES[i]]).max()),
        )
    collision_offset = 0.0
    for c in tree.iter("collision"):
        origin = c.find("origin")
        if origin is not None:
            values = [float(v) for k in ("xyz", "rpy") for v in origin.get(k, "0 0 0").split()]
            collision_offset = max(collision_offset, float(np.abs(values).max()))
    return joint_diff, collision_offset


def checkout_or_exit(argv: list[str], usage: str) -> Path:
    """The ROS-I checkout given as the first argument; exits 0 with a message when absent."""
    if len(argv) < 2 or not Path(argv[1]).is_dir():
        given = argv[1] if len(argv) > 1 else "(none)"
        print(f"skipped: no abb_experimental checkout at {given}. Usage: {usage}")
        sys.exit(0)
    root = Path(argv[1])
    if not (root / "abb_irb2600_support").is_dir():
        print(f"skipped: {root} has no abb_irb2600_support/ (not an abb_experimental checkout)")
        sys.exit(0)
    return root


def load_link_meshes(root: Path, model: str) -> dict[str, trimesh.Trimesh]:
    """Every link's collision mesh of ``model`` in its link frame (m)."""
    _, table = ROSI_MODELS[model]
    return {link: trimesh.load(root / rel, force="mesh") for link, rel in table.items()}


def surface_points(mesh: trimesh.Trimesh, n: int = 20000) -> Array:
    """The mesh's vertices plus ``n`` points sampled on its faces (m, mesh frame)."""
    return np.vstack([mesh.vertices, trimesh.sample.sample_surface(mesh, n, seed=1)[0]])


def signed_distance(geom: coal.CollisionGeometry, p: Array) -> Array:
    """Signed distance (m) of points ``p`` (N, 3, in the primitive's frame) to a coal primitive."""
    if isinstance(geom, coal.Sphere):
        return np.linalg.norm(p, axis=1) - geom.radius
    if isinstance(geom, coal.Capsule):
        z = np.clip(p[:, 2], -geom.halfLength, geom.halfLength)
        return np.linalg.norm(p - np.c_[0 * z, 0 * z, z], axis=1) - geom.radius
    if isinstance(geom, coal.Box):
        q = np.abs(p) - geom.halfSide
    elif isinstance(geom, coal.Cylinder):
        q = np.c_[np.hypot(p[:, 0], p[:, 1]) - geom.radius, np.abs(p[:, 2]) - geom.halfLength]
    else:
        raise TypeError(f"not a primitive: {type(geom).__name__}")
    return np.linalg.norm(np.maximum(q, 0.0), axis=1) + np.minimum(q.max(axis=1), 0.0)


def protrusion(points_link: Array, prims: list[tuple[coal.CollisionGeometry, Array]]) -> Array:
    """How far (m) each point lies outside the union of ``prims`` (geometry, T_link_prim); >= 0."""
    sd = np.full(len(points_link), np.inf)
    for geom, T in prims:
        R, t = T[:3, :3], T[:3, 3]
        sd = np.minimum(sd, signed_distance(geom, (points_link - t) @ R))
    return np.maximum(sd, 0.0)


def union_volume(prims: list[tuple[coal.CollisionGeometry, Array]], n: int = 400_000) -> float:
    """Volume (m^3) of the union of primitives (geometry, T_link_prim), Monte Carlo over
    their common bounding box (seeded; about 0.3 % standard error at the default ``n``)."""
    lo, hi = np.full(3, np.inf), np.full(3, -np.inf)
    for geom, T in prims:
        if isinstance(geom, coal.Box):
            half = geom.halfSide
        elif isinstance(geom, coal.Sphere):
            half = np.full(3, geom.radius)
        else:
            cap = geom.radius if isinstance(geom, coal.Capsule) else 0.0
            half = np.array([geom.radius, geom.radius, geom.halfLength + cap])
        ext = np.abs(T[:3, :3]) @ half
        lo, hi = np.minimum(lo, T[:3, 3] - ext), np.maximum(hi, T[:3, 3] + ext)
    p = np.random.default_rng(0).uniform(lo, hi, (n, 3))
    inside = np.zeros(n, bool)
    for geom, T in prims:
        inside |= signed_distance(geom, (p - T[:3, 3]) @ T[:3, :3]) <= 0.0
    return float(np.prod(hi - lo) * inside.mean())
