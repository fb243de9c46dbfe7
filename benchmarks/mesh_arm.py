"""The built-in IRB 2600 with every collision primitive written as a triangle mesh (binary STL).

For ``robot_costs.py`` when no URDF with real meshes is at hand: the same shapes as the
primitives, as meshes of a few hundred triangles each (the ROS-Industrial IRB 2600's
collision meshes have 390 to 1482), so coal's BVH path is measured on known geometry.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from robots.urdf_writer import URDF_DIR

SEGMENTS = 48


def _cylinder(radius: float, length: float) -> np.ndarray:
    t = np.linspace(0, 2 * np.pi, SEGMENTS, endpoint=False)
    ring = np.column_stack((radius * np.cos(t), radius * np.sin(t)))
    tris = []
    for i in range(SEGMENTS):
        a, b = ring[i], ring[(i + 1) % SEGMENTS]
        lo, hi = -length / 2, length / 2
        tris += [
            [(*a, lo), (*b, lo), (*b, hi)],
            [(*a, lo), (*b, hi), (*a, hi)],
            [(0, 0, hi), (*a, hi), (*b, hi)],
            [(0, 0, lo), (*b, lo), (*a, lo)],
        ]
    return np.array(tris, float)


def _box(x: float, y: float, z: float) -> np.ndarray:
    h = np.array([x, y, z]) / 2
    v = np.array([[i, j, k] for i in (-1, 1) for j in (-1, 1) for k in (-1, 1)], float) * h
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    return np.array(
        [[v[a], v[b], v[c]] for a, b, c, d in quads for a, b, c in ((a, b, c), (a, c, d))]
    )


def _sphere(radius: float) -> np.ndarray:
    th = np.linspace(0, np.pi, SEGMENTS // 2 + 1)
    ph = np.linspace(0, 2 * np.pi, SEGMENTS + 1)
    P = radius * np.stack(
        (np.sin(th)[:, None] * np.cos(ph), np.sin(th)[:, None] * np.sin(ph),
         np.cos(th)[:, None] * np.ones_like(ph)), axis=-1)  # fmt: skip
    tris = []
    for i in range(len(th) - 1):
        for j in range(len(ph) - 1):
            tris += [
                [P[i, j], P[i + 1, j], P[i + 1, j + 1]],
                [P[i, j], P[i + 1, j + 1], P[i, j + 1]],
            ]
    return np.array(tris, float)


def write_binary_stl(path: Path, tris: np.ndarray) -> None:
    """Triangles (n, 3, 3) in metres as a binary STL."""
    rec = np.zeros(len(tris), dtype=[("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")])
    rec["v"] = tris
    with path.open("wb") as f:
        f.write(b"holecell generated mesh".ljust(80, b" "))
        f.write(np.uint32(len(tris)).tobytes())
        f.write(rec.tobytes())


def meshed_builtin_urdf(folder: Path, model: str = "abb_irb2600_20_165") -> Path:
    """Write the model's URDF with mesh collisions (and the meshes) into ``folder``."""
    text = (URDF_DIR / f"{model}.urdf").read_text()
    count = 0

    def mesh_for(match: re.Match[str]) -> str:
        nonlocal count
        kind, attrs = match.group(1), dict(re.findall(r'(\w+)="([^"]*)"', match.group(2)))
        if kind == "box":
            tris = _box(*map(float, attrs["size"].split()))
        elif kind == "cylinder":
            tris = _cylinder(float(attrs["radius"]), float(attrs["length"]))
        else:
            tris = _sphere(float(attrs["radius"]))
        count += 1
        name = f"mesh_{count}.stl"
        write_binary_stl(folder / name, tris)
        return f'<geometry><mesh filename="{name}"/></geometry>'

    text = re.sub(r"<geometry><(box|cylinder|sphere)([^/]*)/></geometry>", mesh_for, text)
    path = folder / f"{model}_meshes.urdf"
    path.write_text(text)
    return path
