"""The built-in ABB arm models: joint origins, limits and D-H parameters.

Figures come from ``docs/abb_kinematics.md`` (ABB product
specifications). Every chain has six revolute joints with axes z, y, y, x, y, x
in their own joint frames, all joint origins with rpy 0, ``link_6 -> flange``
identity and ``link_6 -> tool0`` rotated +90 deg about y.

ABB publishes no acceleration or jerk limits; the defaults are
``acceleration = ACCEL_PER_SPEED * max speed`` (rad/s^2) and
``jerk = JERK_PER_SPEED * max speed`` (rad/s^3), scaled by the cell's limit
scaling.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

JOINT_NAMES: tuple[str, ...] = ("joint_1", "joint_2", "joint_3", "joint_4", "joint_5", "joint_6")
LINK_NAMES: tuple[str, ...] = (
    "base_link",
    "link_1",
    "link_2",
    "link_3",
    "link_4",
    "link_5",
    "link_6",
)
JOINT_AXES: tuple[str, ...] = ("z", "y", "y", "x", "y", "x")

#: default acceleration limit per unit of maximum speed (1/s)
ACCEL_PER_SPEED = 2.5
#: default jerk limit per unit of maximum speed (1/s^2)
JERK_PER_SPEED = 25.0


@dataclass(frozen=True)
class ArmSpec:
    """Geometry and limits of one ABB model.

    Attributes:
        name: model identifier, e.g. ``abb_irb2600_20_165``.
        title: human-readable name.
        joint_origins_m: six parent-to-child joint origins (m).
        lower_rad, upper_rad: joint position limits (rad).
        max_speed_rad_s: joint speed limits (rad/s).
        reach_m: nominal reach in the model's name (m).
    """

    name: str
    title: str
    joint_origins_m: tuple[tuple[float, float, float], ...]
    lower_rad: tuple[float, ...]
    upper_rad: tuple[float, ...]
    max_speed_rad_s: tuple[float, ...]
    reach_m: float

    @property
    def d1(self) -> float:
        """Height of the J2 axis above the base (m)."""
        return self.joint_origins_m[0][2] + self.joint_origins_m[1][2]

    @property
    def a1(self) -> float:
        """Forward offset of the J2 axis from the J1 axis (m)."""
        return self.joint_origins_m[1][0]

    @property
    def a2(self) -> float:
        """Upper arm length, J2 to J3 (m)."""
        return self.joint_origins_m[2][2]

    @property
    def a3(self) -> float:
        """Vertical offset of the forearm axis above J3 (m)."""
        return self.joint_origins_m[3][2] + self.joint_origins_m[4][2]

    @property
    def d4(self) -> float:
        """Forearm length, J3 to the wrist centre along the forearm (m)."""
        return self.joint_origins_m[3][0] + self.joint_origins_m[4][0]

    @property
    def d6(self) -> float:
        """Wrist centre to flange (m)."""
        return self.joint_origins_m[5][0]

    def limits(self) -> tuple[np.ndarray, np.ndarray]:
        """Lower and upper joint limits (rad) as arrays."""
        return np.array(self.lower_rad), np.array(self.upper_rad)


_PI = math.pi

MODELS: dict[str, ArmSpec] = {
    "abb_irb1600_10_145": ArmSpec(
        name="abb_irb1600_10_145",
        title="ABB IRB 1600-10/1.45",
        joint_origins_m=(
            (0, 0, 0),
            (0.15, 0, 0.4865),
            (0, 0, 0.700),
            (0.300, 0, 0),
            (0.300, 0, 0),
            (0.065, 0, 0),
        ),
        lower_rad=(-3.142, -1.571, -4.276, -3.491, -2.007, -6.981),
        upper_rad=(3.142, 2.094, 1.134, 3.491, 2.007, 6.981),
        max_speed_rad_s=(3.142, 3.142, 3.491, 6.981, 6.981, 8.029),
        reach_m=1.45,
    ),
    "abb_irb2600_20_165": ArmSpec(
        name="abb_irb2600_20_165",
        title="ABB IRB 2600-20/1.65",
        joint_origins_m=(
            (0, 0, 0.445),
            (0.15, 0, 0),
            (0, 0, 0.700),
            (0, 0, 0.115),
            (0.795, 0, 0),
            (0.085, 0, 0),
        ),
        lower_rad=(-3.142, -1.658, -3.142, -6.981, -2.094, -6.981),
        upper_rad=(3.142, 2.705, 1.309, 6.981, 2.094, 6.981),
        max_speed_rad_s=(3.054, 3.054, 3.054, 6.283, 6.283, 8.727),
        reach_m=1.65,
    ),
    "abb_irb4600_60_205": ArmSpec(
        name="abb_irb4600_60_205",
        title="ABB IRB 4600-60/2.05",
        joint_origins_m=(
            (0, 0, 0.495),
            (0.175, 0, 0),
            (0, 0, 0.900),
            (0, 0, 0.175),
            (0.960, 0, 0),
            (0.135, 0, 0),
        ),
        lower_rad=(-3.141, -1.570, -3.141, -6.981, -2.181, -6.981),
        upper_rad=(3.141, 2.617, 1.308, 6.981, 2.094, 6.981),
        max_speed_rad_s=(3.054, 3.054, 3.054, 4.363, 4.363, 6.283),
        reach_m=2.05,
    ),
}

DEFAULT_MODEL = "abb_irb2600_20_165"
