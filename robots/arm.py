"""The arm: a Pinocchio model of a six-axis robot with its tool and the cell's obstacles.

Frames: the cell frame is the world; the robot's ``base_link`` sits at
``T_cell_base`` in it. The tool is attached at ``tool0``; its TCP is
``T_tool0_tcp``. All positions in metres, angles in radians, speeds in rad/s.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike, NDArray

from robots.arm_kinematics import check_given_table, derive_kinematics
from robots.collision import Clearance, CollisionModel
from robots.collision_batch import BatchCollision
from robots.dh import DHTable, fk_dh, point_dh
from robots.errors import JointVectorError, UnknownModelError, UrdfError
from robots.ik import IKResult, solve_opw, solve_opw_many
from robots.limits import narrowed_limits
from robots.models import (
    ACCEL_PER_SPEED,
    DEFAULT_MODEL,
    JERK_PER_SPEED,
    MODELS,
    ArmSpec,
)
from robots.opw import fk_opw
from robots.shapes import Shape
from robots.transforms import invert
from robots.urdf_load import load_urdf
from robots.urdf_writer import URDF_DIR

Array = NDArray[np.float64]

FRAMES = ("tcp", "tool0", "flange")


@dataclass(frozen=True)
class LimitScaling:
    """Scale factors (0, 1] on the joint speed, acceleration and jerk limits."""

    velocity: float = 1.0
    acceleration: float = 1.0
    jerk: float = 1.0


def urdf_path(model: str | Path) -> Path:
    """Path of a built-in model's URDF, or ``model`` itself when it names a URDF file."""
    if str(model) in MODELS:
        return URDF_DIR / f"{model}.urdf"
    path = Path(model)
    if path.suffix == ".xacro":
        raise UrdfError(str(path), "is a xacro file: expand it first (xacro arm.xacro > arm.urdf)")
    if path.suffix == ".urdf":
        if not path.is_file():
            raise UrdfError(str(path), "no such file")
        return path
    raise UnknownModelError(str(model), sorted(MODELS))


class Arm:
    """A six-axis arm in a cell: kinematics, limits, tool and collision checks.

    Any ortho-parallel arm with a spherical wrist (the OPW family) is served from its URDF:
    the IK parameters and the D-H rows are derived from the URDF's joint axes and checked
    against its forward kinematics at load (:mod:`robots.arm_kinematics`).

    Args:
        model: a built-in model name (see :data:`robots.models.MODELS`) or a URDF path.
        T_cell_base: pose of ``base_link`` in the cell frame (4x4).
        scaling: scale factors on the velocity, acceleration and jerk limits.
        dh: a D-H table to use instead of the derived one; refused unless it reproduces the
            URDF (1e-9 m).
        package_paths: folders searched first for ``package://`` mesh URIs.
        position_limits: [[lo, hi] x 6] rad narrowing the URDF's limits (never widening).
    """

    def __init__(
        self,
        model: str | Path = DEFAULT_MODEL,
        T_cell_base: ArrayLike | None = None,
        scaling: LimitScaling | None = None,
        dh: DHTable | None = None,
        package_paths: Sequence[str | Path] = (),
        position_limits: ArrayLike | None = None,
    ) -> None:
        self.urdf_path = urdf_path(model)
        self.spec: ArmSpec | None = MODELS.get(str(model))
        self.loaded = load_urdf(self.urdf_path, package_paths)
        self.model, self._robot_geoms = self.loaded.model, self.loaded.collision
        self.data = self.model.createData()
        self.kinematics = derive_kinematics(self.loaded)
        self.opw = self.kinematics.opw
        self.name = self.spec.name if self.spec else self.urdf_path.stem
        self.joint_names = self.loaded.joint_names
        self.nq = 6
        self.T_cell_base = np.eye(4) if T_cell_base is None else np.asarray(T_cell_base, float)
        self._T_base_cell = invert(self.T_cell_base)
        self.scaling = scaling or LimitScaling()
        self.urdf_lower = self.model.lowerPositionLimit.copy()
        self.urdf_upper = self.model.upperPositionLimit.copy()
        self.lower, self.upper = narrowed_limits(
            self.joint_names, self.urdf_lower, self.urdf_upper, position_limits
        )
        if dh is not None:
            check_given_table(self.loaded, dh, self.lower, self.upper)
        self._dh = dh if dh is not None else self.kinematics.dh
        speed = self.model.velocityLimit.copy()
        self.velocity_limit = speed * self.scaling.velocity
        self.acceleration_limit = ACCEL_PER_SPEED * speed * self.scaling.acceleration
        self.jerk_limit = JERK_PER_SPEED * speed * self.scaling.jerk
        self.T_tool0_tcp = np.eye(4)
        self._T_tcp_tool0 = np.eye(4)
        self.tool_shapes: list[Shape] = []
        self.obstacles: list[Shape] = []
        self._frame_ids = {"tool0": self.model.getFrameId("tool0")}
        self._T_tool0_flange = self.loaded.T_tool0_flange
        self._collision: CollisionModel | None = None
        self._batch: tuple[CollisionModel, BatchCollision] | None = None
        self.clearance_margins = Clearance()
        self.disabled_pairs: list[tuple[str, str]] = []

    @property
    def dh(self) -> DHTable:
        """The D-H table of the thermal model (derived from the URDF), or a RobotModelError."""
        if self._dh is None:
            raise UrdfError(str(self.urdf_path), f"no D-H table: {self.kinematics.dh_problem}")
        return self._dh

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

    def link_names(self) -> set[str]:
        """The names of the URDF's links and frames."""
        return {f.name for f in self.model.frames}

    def set_disabled_pairs(self, pairs: Sequence[tuple[str, str]]) -> None:
        """Pairs of links never checked against each other (a MoveIt SRDF's
        ``disable_collisions``), besides the adjacent ones and those touching at q = 0; a
        link the URDF does not have is refused."""
        unknown = sorted({n for pair in pairs for n in pair} - self.link_names())
        if unknown:
            raise UrdfError(str(self.urdf_path), f"has no links {unknown}")
        self.disabled_pairs = [(a, b) for a, b in pairs]
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
                self.model,
                self._robot_geoms,
                self.tool_shapes,
                in_base,
                self.clearance_margins,
                self.disabled_pairs,
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
        T = self.T_cell_base @ self.data.oMf[self._frame_ids["tool0"]].homogeneous
        if frame == "tcp":
            return T @ self.T_tool0_tcp
        return T @ self._T_tool0_flange if frame == "flange" else T

    def fk_dh(self, q: ArrayLike, frame: str = "tcp") -> Array:
        """Like :meth:`fk` but closed-form and vectorised; ``q`` may be (N, 6) for (N, 4, 4).

        From the D-H table; for a chain without a D-H form (J1 about -z) from the OPW
        parameters, which the URDF check at load holds to the same 1e-9 m.
        """
        if frame not in FRAMES:
            raise ValueError(f"frame must be one of {FRAMES}, got {frame!r}")
        T_base = fk_dh(self._dh, q) if self._dh is not None else fk_opw(self.opw, q)
        T = self.T_cell_base @ T_base
        if frame == "tcp":
            return T @ self.T_tool0_tcp
        return T @ self._T_tool0_flange if frame == "flange" else T

    def tcp_positions(self, q: ArrayLike) -> Array:
        """TCP positions (N, 3) in the cell frame (m) for configurations ``q`` (N, 6) rad.

        Equal to ``fk_dh(q, "tcp")[:, :3, 3]`` (to rounding); faster where only positions are
        needed (the TCP-step rule of motion checks samples many configurations).
        """
        if self._dh is None:
            return self.fk_dh(q, "tcp")[..., :3, 3]
        p_base = point_dh(self._dh, q, self.T_tool0_tcp[:3, 3])
        return p_base @ self.T_cell_base[:3, :3].T + self.T_cell_base[:3, 3]

    def ik(self, T_cell_tcp: ArrayLike) -> IKResult:
        """Every joint solution placing the TCP at ``T_cell_tcp`` (see :mod:`robots.ik`)."""
        T_base_tool0 = self._T_base_cell @ np.asarray(T_cell_tcp, float) @ self._T_tcp_tool0
        return solve_opw(self.opw, T_base_tool0, self.lower, self.upper)

    def ik_many(self, T_cell_tcp: ArrayLike) -> list[IKResult]:
        """:meth:`ik` of each pose of ``T_cell_tcp`` (P, 4, 4), the same results, in one call
        (:func:`robots.ik.solve_opw_many`)."""
        T = [self._T_base_cell @ P @ self._T_tcp_tool0 for P in np.asarray(T_cell_tcp, float)]
        return solve_opw_many(self.opw, np.array(T), self.lower, self.upper)

    # -- collision ---------------------------------------------------------------------------
    def in_collision(self, q: ArrayLike) -> bool:
        """True when the arm touches itself (non-adjacent links) or touches an obstacle."""
        return self.collision.in_collision(self.check_q(q))

    def in_collision_each(self, Q: ArrayLike) -> NDArray[np.bool_]:
        """:meth:`in_collision` of each row of ``Q`` (N, 6) rad, in one batch call (the same
        answers; :class:`robots.collision_batch.BatchCollision`)."""
        arr = np.asarray(Q, dtype=float).reshape(-1, self.nq)
        if not np.all(np.isfinite(arr)):
            raise JointVectorError(Q, 6)
        return self._batch_checker().each(arr)

    def in_collision_any(self, Q: ArrayLike) -> bool:
        """True when a row of ``Q`` (N, 6) rad is in collision (:meth:`in_collision`), checked
        in row order up to the first hit, in one batch call."""
        arr = np.asarray(Q, dtype=float).reshape(-1, self.nq)
        if not np.all(np.isfinite(arr)):
            raise JointVectorError(Q, 6)
        return bool(self._batch_checker().any_hit([arr.T])[0])

    def _batch_checker(self) -> BatchCollision:
        collision = self.collision
        if self._batch is None or self._batch[0] is not collision:
            self._batch = (collision, BatchCollision(collision))
        return self._batch[1]

    def colliding_pairs(self, q: ArrayLike) -> list[tuple[str, str]]:
        """Names of the geometry pairs in contact at ``q``."""
        return self.collision.colliding_pairs(self.check_q(q))

    def clearance(self, q: ArrayLike) -> float:
        """Smallest distance (m) between any checked pair at ``q``; negative when penetrating."""
        return self.collision.clearance(self.check_q(q))[0]
