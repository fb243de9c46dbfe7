"""Write the URDF of a built-in model from its figures (:mod:`robots.models`).

The shipped files ``robots/urdf/<model>.urdf`` are this writer's output; a
test keeps them equal. Collision geometry is boxes and cylinders per link
(URDF has no capsule) fitted to enclose the ROS-Industrial collision meshes of
the same arms (:mod:`robots.arm_shapes`, ``benchmarks/fit_link_shapes.py``).

Run ``python -m robots.urdf_writer`` to rewrite the shipped files.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from robots.arm_shapes import LINK_PRIMITIVES
from robots.models import JOINT_AXES, JOINT_NAMES, LINK_NAMES, MODELS, ArmSpec

URDF_DIR = Path(__file__).parent / "urdf"

_AXIS_VEC = {"x": "1 0 0", "y": "0 1 0", "z": "0 0 1"}
#: rpy that turns a primitive's local z axis onto the named axis
_AXIS_RPY = {"x": (0.0, np.pi / 2, 0.0), "y": (-np.pi / 2, 0.0, 0.0), "z": (0.0, 0.0, 0.0)}


@dataclass(frozen=True)
class LinkShape:
    """One primitive of a link, its centre in the link's own frame (m)."""

    link: str
    kind: str  # "box" | "cylinder" | "sphere"
    size: tuple[float, ...]  # box (x, y, z); cylinder (radius, length); sphere (radius,)
    center_link_m: tuple[float, float, float]
    axis: str = "z"  # cylinder axis


def link_shapes(spec: ArmSpec) -> list[LinkShape]:
    """The enclosing primitives of every link of a model (:mod:`robots.arm_shapes`, m)."""
    return [
        LinkShape(link, kind, size, xyz, axis)
        for link, kind, size, xyz, axis in LINK_PRIMITIVES[spec.name]
    ]


def _fmt(values: Iterable[float]) -> str:
    return " ".join(f"{float(v):.6g}" for v in values)


def _geometry_xml(shape: LinkShape) -> str:
    if shape.kind == "box":
        return f'<box size="{_fmt(shape.size)}"/>'
    if shape.kind == "cylinder":
        return f'<cylinder radius="{shape.size[0]:.6g}" length="{shape.size[1]:.6g}"/>'
    return f'<sphere radius="{shape.size[0]:.6g}"/>'


def _link_xml(link: str, shapes: list[LinkShape]) -> list[str]:
    lines = [f'  <link name="{link}">']
    for shape in shapes:
        xyz = _fmt(shape.center_link_m)
        rpy = _fmt(_AXIS_RPY[shape.axis] if shape.kind == "cylinder" else (0, 0, 0))
        geometry = _geometry_xml(shape)
        for tag in ("visual", "collision"):
            lines += [
                f"    <{tag}>",
                f'      <origin xyz="{xyz}" rpy="{rpy}"/>',
                f"      <geometry>{geometry}</geometry>",
            ]
            if tag == "visual":
                lines.append(
                    '      <material name="abb_orange"><color rgba="0.93 0.45 0.0 1"/></material>'
                )
            lines.append(f"    </{tag}>")
    lines.append("  </link>")
    return lines


def urdf_text(spec: ArmSpec) -> str:
    """The URDF document of a model."""
    shapes = link_shapes(spec)
    lines = [
        '<?xml version="1.0"?>',
        f"<!-- {spec.title}: written by robots/urdf_writer.py from docs/abb_kinematics.md. -->",
        f'<robot name="{spec.name}">',
    ]
    for link in LINK_NAMES:
        lines += _link_xml(link, [s for s in shapes if s.link == link])
    lines += ['  <link name="base"/>', '  <link name="flange"/>', '  <link name="tool0"/>']
    for i, name in enumerate(JOINT_NAMES):
        lines += [
            f'  <joint name="{name}" type="revolute">',
            f'    <parent link="{LINK_NAMES[i]}"/>',
            f'    <child link="{LINK_NAMES[i + 1]}"/>',
            f'    <origin xyz="{_fmt(spec.joint_origins_m[i])}" rpy="0 0 0"/>',
            f'    <axis xyz="{_AXIS_VEC[JOINT_AXES[i]]}"/>',
            f'    <limit lower="{spec.lower_rad[i]}" upper="{spec.upper_rad[i]}" '
            f'effort="0" velocity="{spec.max_speed_rad_s[i]}"/>',
            "  </joint>",
        ]
    fixed = (
        ("base_link-base", "base_link", "base", "0 0 0"),
        ("joint_6-flange", "link_6", "flange", "0 0 0"),
        ("link_6-tool0", "link_6", "tool0", f"0 {np.pi / 2:.17g} 0"),
    )
    for name, parent, child, rpy in fixed:
        lines += [
            f'  <joint name="{name}" type="fixed">',
            f'    <parent link="{parent}"/>',
            f'    <child link="{child}"/>',
            f'    <origin xyz="0 0 0" rpy="{rpy}"/>',
            "  </joint>",
        ]
    lines.append("</robot>")
    return "\n".join(lines) + "\n"


def write_all(directory: Path = URDF_DIR) -> list[Path]:
    """Write every built-in model's URDF into ``directory``; returns the paths."""
    directory.mkdir(parents=True, exist_ok=True)
    paths = []
    for spec in MODELS.values():
        path = directory / f"{spec.name}.urdf"
        path.write_text(urdf_text(spec))
        paths.append(path)
    return paths


if __name__ == "__main__":
    for written in write_all():
        print(written)
