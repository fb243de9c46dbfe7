"""Poses and the strict base of the cell file's schema (:mod:`cell.config`).

A pose is ``{xyz: [...], rpy: [...]}`` or ``{xyz: [...], quat_xyzw: [...]}``: position in
metres, roll-pitch-yaw in radians or a unit quaternion ``[x, y, z, w]``.
"""

from __future__ import annotations

from typing import Annotated, Any

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, field_validator

from robots.transforms import pose_to_matrix

#: a normal whose length differs from 1 by more than this is an error
UNIT_TOL = 1e-3

Vec3 = Annotated[list[float], Field(min_length=3, max_length=3)]
Positive = Annotated[float, Field(gt=0)]


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)


class Pose(_Strict):
    """A pose: position (m) and either roll-pitch-yaw (rad) or a quaternion [x, y, z, w]."""

    xyz: Vec3
    rpy: Vec3 | None = None
    quat_xyzw: Annotated[list[float], Field(min_length=4, max_length=4)] | None = None

    @field_validator("quat_xyzw")
    @classmethod
    def _unit_quaternion(cls, q: list[float] | None) -> list[float] | None:
        if q is not None and abs(np.linalg.norm(q) - 1.0) > UNIT_TOL:
            raise ValueError("quaternion must have unit length")
        return q

    def model_post_init(self, __context: Any) -> None:
        if (self.rpy is None) == (self.quat_xyzw is None):
            raise ValueError("a pose needs exactly one of rpy or quat_xyzw besides xyz")

    def matrix(self) -> np.ndarray:
        """The 4x4 transform of this pose."""
        return pose_to_matrix(self.xyz, self.rpy, self.quat_xyzw)


IDENTITY = Pose(xyz=[0.0, 0.0, 0.0], rpy=[0.0, 0.0, 0.0])


def unit_normal(v: list[float]) -> list[float]:
    n = float(np.linalg.norm(v))
    if n == 0.0 or not np.isfinite(n):
        raise ValueError("normal must be a non-zero vector")
    if abs(n - 1.0) > UNIT_TOL:
        raise ValueError(f"normal must have unit length (length {n:.6g})")
    return [float(x) / n for x in v]
