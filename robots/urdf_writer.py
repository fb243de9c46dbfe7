"""Write the URDF of a built-in model from its figures (:mod:`robots.models`).

The shipped files ``robots/urdf/<model>.urdf`` are this writer's output; a
test keeps them equal. Collision geometry is coarse primitives that enclose
each real link with a margin (URDF has no capsule: cylinders, spheres and
boxes only). The lower arm (link_2) sits beside the plane of the forearm, as
on ABB's arms whose J3 folds the forearm back past it. Shapes are laid out
at q = 0, where every link frame is axis-aligned with ``base_link``, and
shifted into their link frames.

Run ``python -m robots.urdf_writer`` to rewrite the shipped files.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from robots.models import JOINT_AXES, JOINT_NAMES, LINK_NAMES, MODELS, ArmSpec

URDF_DIR = Path(__file__).parent / "urdf"

_AXIS_VEC = {"x": "1 0 0", "y": "0 1 0", "z": "0 0 1"}
#: rpy that turns a primitive's local z axis onto the named axis
_AXIS_RPY = {"x": (0.0, np.pi / 2, 0.0), "y": (-np.pi / 2, 0.0, 0.0), "z": (0.0, 0.0, 0.0)}


@dataclass(frozen=True)
class LinkShape:
    """One primitive of a link, laid out at q = 0 in base coordinates (m)."""

    link: str
    kind: str  # "box" | "cylinder" | "sphere"
    size: tuple[float, ...]  # box (x, y, z); cylinder (radius, length); sphere (radius,)
    center_base_m: tuple[float, float, float]
    axis: str = "z"  # cylinder axis


def link_origins_at_zero(spec: ArmSpec) -> dict[str, np.ndarray]:
    """Position of every link frame in ``base_link`` at q = 0 (m)."""
    origins = {"base_link": np.zeros(3)}
    p = np.zeros(3)
    for link, offset in zip(LINK_NAMES[1:], spec.joint_origins_m, strict=True):
        p = p + np.asarray(offset, dtype=float)
        origins[link] = p
    return origins


def link_shapes(spec: ArmSpec) -> list[LinkShape]:
    """The enclosing primitives of every link of a model (m)."""
    s = spec.scale
    o = link_origins_at_zero(spec)
    a1, d1, a2, a3, d4, d6 = spec.a1, spec.d1, spec.a2, spec.a3, spec.d4, spec.d6
    z_elbow = d1 + a2
    z_fore = d1 + a2 + a3
    x_j4 = o["link_4"][0]
    x_fore0 = max(x_j4, a1 + 0.2 * s)  # the rotating forearm starts ahead of the elbow housing
    x_wrist = a1 + d4
    turret_top = d1 - 0.12 * s
    return [
        LinkShape("base_link", "box", (0.62 * s, 0.52 * s, 0.2 * s), (-0.04 * s, 0.0, 0.1 * s)),
        LinkShape(
            "link_1",
            "cylinder",
            (0.25 * s, turret_top - 0.2 * s),
            (0.0, 0.0, 0.5 * (turret_top + 0.2 * s)),
        ),
        LinkShape(
            "link_1",
            "box",
            (a1 + 0.34 * s, 0.62 * s, 0.26 * s),
            (0.5 * a1 - 0.05 * s, -0.08 * s, d1),
        ),
        # the lower arm runs beside the arm plane, so the forearm folds past it (J3 to -180 deg)
        LinkShape("link_2", "cylinder", (0.12 * s, a2 + 0.26 * s), (a1, -0.23 * s, d1 + 0.5 * a2)),
        LinkShape(
            "link_3",
            "box",
            (x_fore0 - a1 + 0.27 * s, 0.3 * s, a3 + 0.26 * s),
            (0.5 * (a1 - 0.25 * s + x_fore0 + 0.02 * s), 0.0, 0.5 * (z_elbow + z_fore)),
        ),
        LinkShape(
            "link_4",
            "cylinder",
            (0.09 * s, x_wrist - 0.1 * s - x_fore0),
            (0.5 * (x_fore0 + x_wrist - 0.1 * s), 0.0, z_fore),
            axis="x",
        ),
        LinkShape("link_5", "sphere", (0.1 * s,), (x_wrist, 0.0, z_fore)),
        LinkShape(
            "link_6", "cylinder", (0.05 * s, d6), (x_wrist + 0.5 * d6, 0.0, z_fore), axis="x"
        ),
    ]


def _fmt(values: object) -> str:
    return " ".join(f"{float(v):.6g}" for v in values)  # type: ignore[union-attr]


def _geometry_xml(shape: LinkShape) -> str:
    if shape.kind == "box":
        return f'<box size="{_fmt(shape.size)}"/>'
    if shape.kind == "cylinder":
        return f'<cylinder radius="{shape.size[0]:.6g}" length="{shape.size[1]:.6g}"/>'
    return f'<sphere radius="{shape.size[0]:.6g}"/>'


def _link_xml(link: str, shapes: list[LinkShape], origin: np.ndarray) -> list[str]:
    lines = [f'  <link name="{link}">']
    for shape in shapes:
        xyz = _fmt(np.asarray(shape.center_base_m) - origin)
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
    origins = link_origins_at_zero(spec)
    shapes = link_shapes(spec)
    lines = [
        '<?xml version="1.0"?>',
        f"<!-- {spec.title}: written by robots/urdf_writer.py from docs/abb_kinematics.md. -->",
        f'<robot name="{spec.name}">',
    ]
    for link in LINK_NAMES:
        lines += _link_xml(link, [s for s in shapes if s.link == link], origins[link])
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
