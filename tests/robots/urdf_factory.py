"""Test arms written as URDF files with box meshes (ASCII STL / OBJ written by hand).

An arm is given at q = 0 in the base frame: joint positions, axis directions and the world
orientation of each joint frame (so origins may carry rpy, as real URDFs do). The writer turns
that into parent-relative ``<origin>``/``<axis>`` elements.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation


@dataclass(frozen=True)
class ArmSketch:
    """A six-joint arm at q = 0 (m, unit vectors, base frame)."""

    points: tuple[tuple[float, float, float], ...]
    axes: tuple[tuple[float, float, float], ...]
    frame_rpy: tuple[tuple[float, float, float], ...] = ((0.0, 0.0, 0.0),) * 6
    flange_xyz: tuple[float, float, float] = (0.1, 0.0, 0.0)  # from joint 6, in its frame
    tool0_rpy: tuple[float, float, float] = (0.0, np.pi / 2, 0.0)  # from the flange
    limits: tuple[tuple[float, float], ...] = ((-3.0, 3.0),) * 6
    names: tuple[str, ...] = tuple(f"joint_{i}" for i in range(1, 7))
    links: tuple[str, ...] = ("base_link", *(f"link_{i}" for i in range(1, 7)))
    mesh_uris: dict[str, str] = field(default_factory=dict)  # link -> collision mesh URI
    visual_uris: dict[str, str] = field(default_factory=dict)  # link -> visual mesh URI

    def with_(self, **changes: object) -> ArmSketch:
        """A copy with some fields changed."""
        return replace(self, **changes)


#: an ABB-like arm (the IRB 2600's figures): upper arm up, forearm forward at q = 0
ABB_LIKE = ArmSketch(
    points=(
        (0, 0, 0.445),
        (0.15, 0, 0.445),
        (0.15, 0, 1.145),
        (0.15, 0, 1.26),
        (0.945, 0, 1.26),
        (1.03, 0, 1.26),
    ),
    axes=((0, 0, 1), (0, 1, 0), (0, 1, 0), (1, 0, 0), (0, 1, 0), (1, 0, 0)),
)

#: a KUKA-like arm: J1 about -z, upper arm forward at q = 0, J4 and J6 about -x, a lateral
#: wrist offset b = 0.02 m, frames turned (rpy on the origins) and joint names of its own
KUKA_LIKE = ArmSketch(
    points=(
        (0, 0, 0.3),
        (0.26, 0, 0.675),
        (0.94, 0, 0.675),
        (0.94, 0.02, 0.64),
        (1.61, 0.02, 0.64),
        (1.61, 0.02, 0.64),
    ),
    axes=((0, 0, -1), (0, 1, 0), (0, 1, 0), (-1, 0, 0), (0, 1, 0), (-1, 0, 0)),
    frame_rpy=(
        (0, 0, 0),
        (np.pi / 2, 0, 0),
        (np.pi / 2, 0, 0),
        (0, 0, 0.3),
        (0, 0, 0),
        (0.2, 0, 0),
    ),
    names=tuple(f"joint_a{i}" for i in range(1, 7)),
    links=("base_link", *(f"arm_{i}" for i in range(1, 7))),
)


def _rpy_of(R: np.ndarray) -> tuple[float, float, float]:
    return tuple(Rotation.from_matrix(R).as_euler("xyz").tolist())


def _fmt(v: object) -> str:
    return " ".join(repr(float(x)) for x in np.asarray(v, float))


def write_urdf(path: Path, arm: ArmSketch) -> Path:
    """Write ``arm`` as a URDF at ``path`` (meshes by the URIs given; none by default)."""
    Rs = [np.eye(3)] + [Rotation.from_euler("xyz", r).as_matrix() for r in arm.frame_rpy]
    ps = [np.zeros(3)] + [np.asarray(p, float) for p in arm.points]
    out = [f'<robot name="{path.stem}">']
    for link in (*arm.links, "flange", "tool0"):
        out.append(f'  <link name="{link}">')
        if link in arm.visual_uris:
            uri = arm.visual_uris[link]
            out.append(f'    <visual><geometry><mesh filename="{uri}"/></geometry></visual>')
        if link in arm.mesh_uris:
            out.append(
                '    <collision><origin xyz="0 0 0" rpy="0 0 0"/>'
                f'<geometry><mesh filename="{arm.mesh_uris[link]}"/></geometry></collision>'
            )
        out.append("  </link>")
    for i in range(6):
        R_parent, p_parent = Rs[i], ps[i]
        xyz = R_parent.T @ (ps[i + 1] - p_parent)
        rpy = _rpy_of(R_parent.T @ Rs[i + 1])
        axis = Rs[i + 1].T @ np.asarray(arm.axes[i], float)
        lo, hi = arm.limits[i]
        out += [
            f'  <joint name="{arm.names[i]}" type="revolute">',
            f'    <parent link="{arm.links[i]}"/><child link="{arm.links[i + 1]}"/>',
            f'    <origin xyz="{_fmt(xyz)}" rpy="{_fmt(rpy)}"/>',
            f'    <axis xyz="{_fmt(axis)}"/>',
            f'    <limit lower="{lo}" upper="{hi}" effort="0" velocity="3.0"/>',
            "  </joint>",
        ]
    out += [
        '  <joint name="link_6-flange" type="fixed">',
        f'    <parent link="{arm.links[6]}"/><child link="flange"/>',
        f'    <origin xyz="{_fmt(arm.flange_xyz)}" rpy="{_fmt(_rpy_of(Rs[6].T))}"/>',
        "  </joint>",
        '  <joint name="flange-tool0" type="fixed">',
        '    <parent link="flange"/><child link="tool0"/>',
        f'    <origin xyz="0 0 0" rpy="{_fmt(arm.tool0_rpy)}"/>',
        "  </joint>",
        "</robot>",
    ]
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("\n".join(out) + "\n")
    return path


def box_triangles(size: tuple[float, float, float]) -> tuple[np.ndarray, np.ndarray]:
    """Vertices (8, 3) and triangles (12, 3) of a box centred on the origin (m)."""
    h = np.asarray(size, float) / 2
    v = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], float) * h
    faces = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    tris = []
    for a, b, c, d in faces:
        tris += [(a, b, c), (a, c, d)]
    return v, np.array(tris)


def write_stl(path: Path, size: tuple[float, float, float]) -> Path:
    """An ASCII STL of a box (m)."""
    v, tris = box_triangles(size)
    lines = ["solid box"]
    for t in tris:
        a, b, c = v[t]
        n = np.cross(b - a, c - a)
        n /= np.linalg.norm(n)
        lines += [f"facet normal {_fmt(n)}", "outer loop"]
        lines += [f"vertex {_fmt(p)}" for p in (a, b, c)]
        lines += ["endloop", "endfacet"]
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("\n".join([*lines, "endsolid box"]) + "\n")
    return path


def write_obj(path: Path, size: tuple[float, float, float]) -> Path:
    """A Wavefront OBJ of a box (m)."""
    v, tris = box_triangles(size)
    lines = [f"v {_fmt(p)}" for p in v] + [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in tris]
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("\n".join(lines) + "\n")
    return path


def write_dae(path: Path, size: tuple[float, float, float]) -> Path:
    """A minimal COLLADA 1.4 file of a box (m): one triangle mesh, one node."""
    v, tris = box_triangles(size)
    positions = " ".join(_fmt(p) for p in v)
    indices = " ".join(str(i) for i in tris.ravel())
    text = f"""<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset><unit name="meter" meter="1"/><up_axis>Z_UP</up_axis></asset>
  <library_geometries>
    <geometry id="box" name="box"><mesh>
      <source id="box-pos">
        <float_array id="box-pos-array" count="{v.size}">{positions}</float_array>
        <technique_common><accessor source="#box-pos-array" count="{len(v)}" stride="3">
          <param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/>
        </accessor></technique_common>
      </source>
      <vertices id="box-vtx"><input semantic="POSITION" source="#box-pos"/></vertices>
      <triangles count="{len(tris)}">
        <input semantic="VERTEX" source="#box-vtx" offset="0"/><p>{indices}</p>
      </triangles>
    </mesh></geometry>
  </library_geometries>
  <library_visual_scenes><visual_scene id="scene">
    <node id="box-node"><instance_geometry url="#box"/></node>
  </visual_scene></library_visual_scenes>
  <scene><instance_visual_scene url="#scene"/></scene>
</COLLADA>
"""
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)
    return path
