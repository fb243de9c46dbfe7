"""Collision shapes: primitives with a pose, turned into coal geometries.

A :class:`Shape` is what the cell file describes: ``box`` (full edge lengths
x, y, z), ``cylinder`` and ``capsule`` (radius, length along the local z axis,
centred on the origin), ``sphere`` (radius), ``mesh`` (a
:class:`robots.meshes.TriangleMesh` in the shape's frame, no sizes). Sizes in metres; ``T`` is the
pose of the shape's centre in its parent frame (the cell frame for obstacles,
``tool0`` for tool shapes).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import coal
import numpy as np
from numpy.typing import NDArray

from robots.errors import ShapeError
from robots.meshes import TriangleMesh

KIND_SIZES: dict[str, tuple[str, ...]] = {
    "box": ("x", "y", "z"),
    "cylinder": ("radius", "length"),
    "capsule": ("radius", "length"),
    "sphere": ("radius",),
    "mesh": (),
}


@dataclass(frozen=True)
class Shape:
    """A primitive with its pose ``T`` (4x4) in its parent frame; sizes in metres."""

    kind: str
    size: tuple[float, ...]
    T: NDArray[np.float64] = field(default_factory=lambda: np.eye(4))
    name: str = "shape"
    mesh: TriangleMesh | None = None

    def __post_init__(self) -> None:
        if self.kind not in KIND_SIZES:
            raise ShapeError(
                self.name, f"unknown shape kind {self.kind!r} (one of {sorted(KIND_SIZES)})"
            )
        expected = len(KIND_SIZES[self.kind])
        if len(self.size) != expected:
            raise ShapeError(
                self.name,
                f"{self.kind} takes {expected} sizes {KIND_SIZES[self.kind]}, got {self.size!r}",
            )
        if not all(np.isfinite(v) and v > 0 for v in self.size):
            raise ShapeError(self.name, f"sizes must be positive metres, got {self.size!r}")
        if (self.kind == "mesh") != (self.mesh is not None):
            raise ShapeError(self.name, "a mesh shape, and only a mesh shape, carries a mesh")

    def geometry(self) -> coal.CollisionGeometry:
        """The coal geometry of this shape."""
        if self.kind == "box":
            return coal.Box(*self.size)
        if self.kind == "cylinder":
            return coal.Cylinder(self.size[0], self.size[1])
        if self.kind == "capsule":
            return coal.Capsule(self.size[0], self.size[1])
        if self.mesh is not None:
            return self.mesh.geometry()
        return coal.Sphere(self.size[0])

    def bounding_radius(self) -> float:
        """Radius of a sphere about the shape's centre that encloses it (m)."""
        if self.kind == "box":
            return 0.5 * float(np.linalg.norm(self.size))
        if self.kind == "sphere":
            return float(self.size[0])
        if self.mesh is not None:
            return self.mesh.bounding_radius()
        radius, length = self.size
        if self.kind == "capsule":
            return 0.5 * length + radius
        return float(np.hypot(radius, 0.5 * length))

    def moved(self, T_new_parent: NDArray[np.float64]) -> Shape:
        """The same shape with its pose expressed in another frame: ``T_new_parent @ T``."""
        return Shape(self.kind, self.size, T_new_parent @ self.T, self.name, self.mesh)
