"""Shapes with a pose in the cell file (:mod:`cell.config`): box, cylinder, capsule, sphere, mesh.

Lengths in metres; a mesh path is relative to the cell file (:mod:`cell.config.mesh`).
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any

import numpy as np
from pydantic import Field

from cell.config.mesh import MeshSpec
from cell.config.pose import IDENTITY, Pose, Positive, _Strict
from robots import Shape


class Box(_Strict):
    size: Annotated[list[Positive], Field(min_length=3, max_length=3)]


class Cylinder(_Strict):
    radius: Positive
    length: Positive


class Sphere(_Strict):
    radius: Positive


SHAPE_KINDS = ("box", "cylinder", "capsule", "sphere", "mesh")


class ShapeSpec(_Strict):
    """One shape with a pose: exactly one of ``box``, ``cylinder``, ``capsule``, ``sphere``,
    ``mesh`` (:mod:`cell.config.mesh`)."""

    box: Box | None = None
    cylinder: Cylinder | None = None
    capsule: Cylinder | None = None
    sphere: Sphere | None = None
    mesh: MeshSpec | None = None
    pose: Pose = IDENTITY
    name: str | None = None

    def model_post_init(self, __context: Any) -> None:
        kinds = [k for k in SHAPE_KINDS if getattr(self, k) is not None]
        if len(kinds) != 1:
            raise ValueError(f"a shape needs exactly one of {', '.join(SHAPE_KINDS)} (got {kinds})")

    def to_shape(
        self, T_parent: np.ndarray, default_name: str, base_dir: Path | None = None
    ) -> Shape:
        """The :class:`robots.Shape`, its pose premultiplied by ``T_parent``; a mesh path is
        taken relative to ``base_dir``."""
        name = self.name or default_name
        T = T_parent @ self.pose.matrix()
        if self.mesh is not None:
            return Shape("mesh", (), T, name, self.mesh.load(base_dir))
        if self.box is not None:
            return Shape("box", tuple(self.box.size), T, name)
        if self.sphere is not None:
            return Shape("sphere", (self.sphere.radius,), T, name)
        kind = "cylinder" if self.cylinder is not None else "capsule"
        dims = self.cylinder or self.capsule
        return Shape(kind, (dims.radius, dims.length), T, name)
