"""The arm: a Pinocchio model of an ABB robot with its tool and the cell's obstacles.

Frames: the cell frame is the world; the robot's ``base_link`` sits at
``T_cell_base`` in it. The tool is attached at ``tool0``; its TCP is
``T_tool0_tcp``. All positions in metres, angles in radians, speeds in rad/s.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike, NDArray

from robots.collision import Clearance, CollisionModel
from robots.dh import DHTable, dh_table, fk_dh
from robots.errors import JointVectorError, UnknownModelError, UrdfError
from robots.ik import IKResult, solve_ik
from robots.models import (
    ACCEL_PER_SPEED,
    DEFAULT_MODEL,
    JERK_PER_SPEED,
    JOINT_NAMES,
    MODELS,
    ArmSpec,
)
from robots.shapes import Shape
from robots.transforms import invert
from robots.urdf_writer import URDF_DIR

Array = NDArray[np.float64]

FRAMES = ("tcp", "tool0", "flange")
#: ``tool0`` is ``flange`` (= link_6) turned +90 deg about y; this maps flange into tool0
_T_TOOL0_FLANGE = np.array(
    [[0.0, 0.0, -1.0, 0.0], [0.0, 1.0, 0.0, 0.0], [1.0, 0.0, 0.0, 0.0], [0, 0, 0, 1.0]]
)


@dataclass(frozen=True)
class LimitScaling:
    """Scale factors (0, 1] on the joint speed, acceleration and jerk limits."""

    velocity: float = 1.0
    acceleration: float = 1.0
    jerk: float = 1.0


def urdf_path(model: str) -> Path:
    """Path of a built-in model's URDF, or ``model`` itself when it names a URDF file."""
    if model in MODELS:
        return URDF_DIR / f"{model}.urdf"
    path = Path(model)
    if path.suffix == ".urdf" and path.is_file():
        return path
    raise UnknownModelError(model, sorted(MODELS))


def _load_pinocchio(path: Path) -> tuple[pin.Model, pin.GeometryModel]:
    try:
        model, collision, _visual = pin.buildModelsFromUrdf(str(path))
    except (RuntimeError, ValueError) as exc:
        raise UrdfError(str(path), f"cannot be read by Pinocchio: {exc}") from exc
    names = list(model.names)[1:]
    if tuple(names) != JOINT_NAMES:
        raise UrdfError(str(path), f"expected joints {JOINT_NAMES}, found {tuple(names)}")
    for frame in ("tool0", "flange"):
        if not model.existFrame(frame):
            raise UrdfError(str(path), f"has no frame {frame!r}")
    return model, collision


class Arm:
    """An ABB arm in a cell: kinematics, limits, tool and collision checks.

    Args:
        model: a built-in model name (see :data:`robots.models.MODELS`) or a URDF path.
            A foreign URDF needs the ABB joint layout and a matching built-in D-H table
            for inverse kinematics (give it with ``dh``).
        T_cell_base: pose of ``base_link`` in the cell frame (4x4).
        scaling: scale factors on the velocity, acceleration and jerk limits.
        dh: D-H table for inverse kinematics; defaults to the built-in model's.
    """

    def __init__(
        self,
        model: str = DEFAULT_MODEL,
        T_cell_base: ArrayLike | None = None,
        scaling: LimitScaling | None = None,
        dh: DHTable | None = None,
    ) -> None:
        self.urdf_path = urdf_path(model)
        self.spec: ArmSpec | None = MODELS.get(model)
        self.model, self._robot_geoms = _load_pinocchio(self.urdf_path)
        self.data = self.model.createData()
        if dh is None and self.spec is None:
            raise UrdfError(str(self.urdf_path), "a foreign URDF needs a D-H table for IK (dh=...)")
        self.dh = dh if dh is not None else dh_table(self.spec)
        self.name = self.spec.name if self.spec else self.urdf_path.stem
        self.joint_names = JOINT_NAMES
        self.nq = 6
        self.T_cell_base = np.eye(4) if T_cell_base is None else np.asarray(T_cell_base, float)
        self._T_base_cell = invert(self.T_cell_base)
        self.scaling = scaling or LimitScaling()
        self.lower = self.model.lowerPositionLimit.copy()
        self.upper = self.model.upperPositionLimit.copy()
        speed = self.model.velocityLimit.copy()
        self.velocity_limit = speed * self.scaling.velocity
        self.acceleration_limit = ACCEL_PER_SPEED * speed * self.scaling.acceleration
        self.jerk_limit = JERK_PER_SPEED * speed * self.scaling.jerk
        self.T_tool0_tcp = np.eye(4)
        self._T_tcp_tool0 = np.eye(4)
        self.tool_shapes: list[Shape] = []
        self.obstacles: list[Shape] = []
        self._frame_ids = {f: self.model.getFrameId(f) for f in ("tool0", "flange")}
        self._collision: CollisionModel | None = None
        self.clearance_margins = Clearance()

    # -- configuration of the cell -------------------------------------------------------
    def set_tool(self, T_tool0_tcp: ArrayLike, shapes: list[Shape] | None = None) -> None:
        """Attach the tool: its TCP pose and its shapes, both relative to ``tool0``."""
        self.T_tool0_tcp = np.asarray(T_tool0_tcp, dtype=float)
        self._T_tcp_tool0 = invert(self.T_tool0_tcp)
        self.tool_shapes = list(shapes or [])
        self._collision = None

    def add_obstacles(self, shapes: list[Shape]) -> None:
        """Add obstacles whose poses are given in the cell frame."""
        self.obstacles.extend(shapes)
        self._collision = None

    def set_clearance(self, robot_m: float, tool_m: float) -> None:
        """Margins (m) kept by every check: arm vs obstacles, tool vs obstacles and arm links."""
        self.clearance_margins = Clearance(robot_m, tool_m)
        self._collision = None

    @property
    def collision(self) -> CollisionModel:
        """The collision model (built on first use, rebuilt after tool or obstacle changes)."""
        if self._collision is None:
            in_base = [s.moved(self._T_base_cell) for s in self.obstacles]
            self._collision = CollisionModel(
                self.model, self._robot_geoms, self.tool_shapes, in_base, self.clearance_margins
            )
        return self._collision

    # -- kinematics ------------------------------------------------------------------------
    def check_q(self, q: ArrayLike) -> Array:
        """``q`` as a float array of six finite joint values (rad), or :class:`JointVectorError`."""
        arr = np.asarray(q, dtype=float)
        if arr.shape != (6,) or not np.all(np.isfinite(arr)):
            raise JointVectorError(q, 6)
        return arr

    def within_limits(self, q: ArrayLike, tol: float = 1e-9) -> bool:
        """True when every joint lies within its position limits (rad)."""
        arr = self.check_q(q)
        return bool(np.all(arr >= self.lower - tol) and np.all(arr <= self.upper + tol))

    def fk(self, q: ArrayLike, frame: str = "tcp") -> Array:
        """``T_cell_<frame>`` (4x4) for ``frame`` in ``tcp``, ``tool0``, ``flange``."""
        if frame not in FRAMES:
            raise ValueError(f"frame must be one of {FRAMES}, got {frame!r}")
        arr = self.check_q(q)
        pin.framesForwardKinematics(self.model, self.data, arr)
        fid = self._frame_ids["flange" if frame == "flange" else "tool0"]
        T = self.T_cell_base @ self.data.oMf[fid].homogeneous
        return T @ self.T_tool0_tcp if frame == "tcp" else T

    def fk_dh(self, q: ArrayLike, frame: str = "tcp") -> Array:
        """Like :meth:`fk` but from the D-H table; ``q`` may be (N, 6) for (N, 4, 4)."""
        if frame not in FRAMES:
            raise ValueError(f"frame must be one of {FRAMES}, got {frame!r}")
        T = self.T_cell_base @ fk_dh(self.dh, q)
        if frame == "tcp":
            return T @ self.T_tool0_tcp
        return T @ _T_TOOL0_FLANGE if frame == "flange" else T

    def ik(self, T_cell_tcp: ArrayLike) -> IKResult:
        """Every joint solution placing the TCP at ``T_cell_tcp`` (see :mod:`robots.ik`)."""
        T_base_tool0 = self._T_base_cell @ np.asarray(T_cell_tcp, float) @ self._T_tcp_tool0
        return solve_ik(self.dh, T_base_tool0, self.lower, self.upper)

    # -- collision ---------------------------------------------------------------------------
    def in_collision(self, q: ArrayLike) -> bool:
        """True when the arm touches itself (non-adjacent links) or touches an obstacle."""
        return self.collision.in_collision(self.check_q(q))

    def colliding_pairs(self, q: ArrayLike) -> list[tuple[str, str]]:
        """Names of the geometry pairs in contact at ``q``."""
        return self.collision.colliding_pairs(self.check_q(q))

    def clearance(self, q: ArrayLike) -> float:
        """Smallest distance (m) between any checked pair at ``q``; negative when penetrating."""
        return self.collision.clearance(self.check_q(q))[0]
