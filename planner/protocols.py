"""What the planner needs from the arm and the cell (structural types).

The planner never imports :mod:`cell`; it works with anything of these shapes.
"""

from __future__ import annotations

from typing import Protocol

import numpy as np
from numpy.typing import ArrayLike, NDArray


class IKResultLike(Protocol):
    """Result of an IK query: every solution within limits, or the reason there is none."""

    solutions: NDArray[np.float64]
    branches: NDArray[np.int64]
    reason: str | None

    @property
    def ok(self) -> bool: ...


class ArmLike(Protocol):
    """The parts of ``robots.Arm`` the planner uses (rad, m, s; cell frame)."""

    joint_names: tuple[str, ...]
    lower: NDArray[np.float64]
    upper: NDArray[np.float64]
    velocity_limit: NDArray[np.float64]
    acceleration_limit: NDArray[np.float64]
    jerk_limit: NDArray[np.float64]

    def ik(self, T_cell_tcp: ArrayLike) -> IKResultLike: ...

    def fk(self, q: ArrayLike, frame: str = "tcp") -> NDArray[np.float64]: ...

    def fk_dh(self, q: ArrayLike, frame: str = "tcp") -> NDArray[np.float64]: ...

    def in_collision(self, q: ArrayLike) -> bool: ...

    def colliding_pairs(self, q: ArrayLike) -> list[tuple[str, str]]: ...

    def within_limits(self, q: ArrayLike, tol: float = 1e-9) -> bool: ...


class HoleLike(Protocol):
    """A hole in the cell frame: centre (m) and unit normal out of the surface."""

    id: str
    position_m: NDArray[np.float64]
    normal: NDArray[np.float64]


class _ToolLike(Protocol):
    standoff_m: float


class _RobotLike(Protocol):
    model: str


class CellLike(Protocol):
    """The parts of ``cell.config.CellConfig`` that :func:`planner.plan_tour` uses."""

    name: str

    @property
    def tool(self) -> _ToolLike: ...

    @property
    def robot(self) -> _RobotLike: ...

    @property
    def raw_text(self) -> str: ...

    def build_arm(self) -> ArmLike: ...

    def holes_in_cell(self) -> list[HoleLike]: ...

    def home_q(self) -> NDArray[np.float64]: ...
