"""The schema of the cell file (``cell.yaml``): robot, tool, part with holes, obstacles,
reference targets, and :class:`CellConfig`, the validated whole (read it with
:func:`cell.config.load_cell`).

Every length is in metres, every angle in radians. The part's holes and obstacles are given
in the part frame, placed in the cell by ``part.base``; environment obstacles and reference
targets are in the cell frame.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Annotated

import numpy as np
from pydantic import Field, PrivateAttr, field_validator

from cell.config.datums import Alignment, Datum, Tolerances
from cell.config.markers import ReferenceMarker, ScaleBar
from cell.config.pose import IDENTITY, Pose, Positive, Vec3, _Strict, unit_normal
from cell.config.shapes import ShapeSpec
from cell.config.srdf import Srdf, read_srdf
from cell.config.step_part import StepSpec
from cell.config.target import CalibrationTargetBoard
from cell.errors import ConfigError
from cell.uncertainty.materials import (
    BUILTIN_MATERIALS,
    DEFAULT_MATERIAL,
    Material,
    MaterialSpec,
    material_field,
)
from robots import DEFAULT_MODEL, Arm, LimitScaling, Shape
from robots.meshes import TriangleMesh

JointRange = Annotated[list[float], Field(min_length=2, max_length=2)]


class Limits(_Strict):
    velocity_scale: Annotated[float, Field(gt=0, le=1)] = 1.0
    acceleration_scale: Annotated[float, Field(gt=0, le=1)] = 1.0
    jerk_scale: Annotated[float, Field(gt=0, le=1)] = 1.0
    #: [[lower, upper] x 6] rad narrowing the URDF's joint limits (a widening is refused)
    position: Annotated[list[JointRange], Field(min_length=6, max_length=6)] | None = None


class Robot(_Strict):
    model: str = DEFAULT_MODEL
    base: Pose = IDENTITY
    #: six joint values (rad), or the name of a ``group_state`` of ``srdf``
    home: (
        Annotated[list[float], Field(min_length=6, max_length=6)]
        | Annotated[str, Field(min_length=1)]
    )
    limits: Limits = Limits()
    #: a MoveIt SRDF (relative to the cell file): disabled collision pairs, named states
    #: (:mod:`cell.config.srdf`)
    srdf: str | None = None
    #: folders (relative to the cell file) searched first for package:// mesh URIs
    package_paths: list[str] = []
    #: ISO 9283 pose repeatability RP (m); None: the maker's figure for the model
    repeatability_m: Annotated[float, Field(gt=0, le=1e-3)] | None = None
    #: margin kept between every arm link and every obstacle (m)
    clearance_m: Annotated[float, Field(ge=0, le=0.5)] = 0.010


class Tool(_Strict):
    tool0_to_tcp: Pose
    standoff_m: Positive
    shapes: list[ShapeSpec] = []
    calibration: str | None = None
    #: margin kept between the tool and every obstacle or arm link (m)
    clearance_m: Annotated[float, Field(ge=0, le=0.5)] = 0.005


class Hole(_Strict):
    id: Annotated[str, Field(min_length=1)]
    position: Vec3
    normal: Vec3
    diameter: Positive
    tolerance: Positive | None = None
    #: GD&T position and size tolerances (:mod:`cell.config.datums`, docs/gdt.md)
    tolerances: Tolerances | None = None

    _unit_normal = field_validator("normal")(lambda cls, v: unit_normal(v))


#: plausible part temperatures (degC): outside, the figure is a mistake (kelvin, a typo)
PART_TEMPERATURE_RANGE_C = (-10.0, 50.0)


class Part(_Strict):
    base: Pose = IDENTITY
    holes: list[Hole] = []
    #: more holes from a CSV, relative to the cell file (:mod:`cell.config.holes_csv`)
    holes_csv: str | None = None
    #: holes, drawing and mesh from the part's STEP file (:mod:`cell.config.step_part`)
    step: StepSpec | None = None
    obstacles: list[ShapeSpec] = []
    #: a built-in name or {name, alpha_per_K, u_alpha_per_K}; None: steel assumed
    material: MaterialSpec | None = None
    #: the part's temperature when a run is given no reading (degC; a conditioned room)
    temperature_c: (
        Annotated[float, Field(ge=PART_TEMPERATURE_RANGE_C[0], le=PART_TEMPERATURE_RANGE_C[1])]
        | None
    ) = None
    #: standard uncertainty of ``temperature_c`` (K)
    u_temperature_K: Annotated[float, Field(gt=0, le=10)] | None = None  # noqa: N815
    #: datum features in precedence and the run's alignment (:mod:`cell.config.datums`)
    datums: list[Datum] = []
    alignment: Alignment | None = None

    _material = field_validator("material", mode="before")(lambda cls, v: material_field(v))
    _step = field_validator("step", mode="before")(
        lambda cls, v: {"path": v} if isinstance(v, str) else v
    )


class Environment(_Strict):
    obstacles: list[ShapeSpec] = []


class ReferenceTarget(_Strict):
    id: Annotated[str, Field(min_length=1)]
    position: Vec3
    normal: Vec3
    diameter: Positive

    _unit_normal = field_validator("normal")(lambda cls, v: unit_normal(v))


class CalibrationTarget(CalibrationTargetBoard):
    """``calibration_target``: the plate board (:mod:`cell.config.target`) and its nominal
    pose in the cell."""

    pose: Pose

    def T_cell_target(self) -> np.ndarray:
        """Nominal pose of the board frame in the cell."""
        return self.pose.matrix()


@dataclass(frozen=True)
class HoleInCell:
    """A hole in the cell frame: centre (m), unit normal out of the surface, diameter (m)."""

    id: str
    position_m: np.ndarray
    normal: np.ndarray
    diameter_m: float
    tolerance_m: float | None


class CellConfig(_Strict):
    """A whole cell file. Build it with :func:`load_cell`."""

    name: Annotated[str, Field(min_length=1)]
    robot: Robot
    tool: Tool
    part: Part
    environment: Environment = Environment()
    reference_targets: list[ReferenceTarget] = []
    calibration_target: CalibrationTarget | None = None
    reference_markers: list[ReferenceMarker] = []
    scale_bars: list[ScaleBar] = []

    _source_path: Path | None = PrivateAttr(default=None)
    _raw_text: str = PrivateAttr(default="")
    #: the part's mesh tessellated from ``part.step`` (m, part frame), when asked for
    _step_mesh: TriangleMesh | None = PrivateAttr(default=None)

    @property
    def source_path(self) -> Path | None:
        """The file this cell was read from."""
        return self._source_path

    @property
    def raw_text(self) -> str:
        """The YAML text as read (stored with every run)."""
        return self._raw_text

    def T_cell_base(self) -> np.ndarray:
        """Pose of the robot's ``base_link`` in the cell frame."""
        return self.robot.base.matrix()

    def T_cell_part(self) -> np.ndarray:
        """Pose of the part frame in the cell frame."""
        return self.part.base.matrix()

    def T_tool0_tcp(self) -> np.ndarray:
        """Pose of the TCP (the stereo head's view frame) relative to ``tool0``."""
        return self.tool.tool0_to_tcp.matrix()

    def home_q(self) -> np.ndarray:
        """The home joint vector (rad): ``robot.home``, or the SRDF's state it names."""
        home = self.robot.home
        if isinstance(home, str):
            srdf = self.srdf()
            if srdf is None:
                raise ConfigError(
                    str(self._source_path or "<cell>"),
                    [
                        (
                            "robot.home",
                            home,
                            "a state name needs robot.srdf (else give 6 values, rad)",
                        )
                    ],
                )
            return np.array(srdf.state(home, list(self.build_robot().joint_names)), dtype=float)
        return np.array(home, dtype=float)

    def srdf(self) -> Srdf | None:
        """``robot.srdf`` read, or None."""
        if self.robot.srdf is None:
            return None
        return read_srdf(self._relative_to_cell(self.robot.srdf))

    def holes_in_cell(self) -> list[HoleInCell]:
        """Every hole with its centre and normal in the cell frame."""
        T = self.T_cell_part()
        return [
            HoleInCell(
                id=h.id,
                position_m=T[:3, :3] @ np.array(h.position) + T[:3, 3],
                normal=T[:3, :3] @ np.array(h.normal),
                diameter_m=h.diameter,
                tolerance_m=h.tolerance,
            )
            for h in self.part.holes
        ]

    @property
    def base_dir(self) -> Path | None:
        """The cell file's folder (relative paths in the file start here)."""
        return None if self._source_path is None else self._source_path.parent

    def tool_shapes(self) -> list[Shape]:
        """The stereo head's shapes, poses relative to ``tool0``."""
        d = self.base_dir
        return [s.to_shape(np.eye(4), f"tool{i}", d) for i, s in enumerate(self.tool.shapes)]

    def obstacle_shapes(self) -> list[Shape]:
        """Part and environment obstacles and the calibration plate, poses in the cell frame."""
        T_part, d = self.T_cell_part(), self.base_dir
        part = [s.to_shape(T_part, f"part{i}", d) for i, s in enumerate(self.part.obstacles)]
        if self._step_mesh is not None:
            part.append(Shape("mesh", (), T_part, "part_step", self._step_mesh))
        env = [
            s.to_shape(np.eye(4), f"env{i}", d) for i, s in enumerate(self.environment.obstacles)
        ]
        t = self.calibration_target
        return part + ([] if t is None else [t.plate_shape(t.T_cell_target())]) + env

    def _relative_to_cell(self, path: str) -> Path:
        p = Path(path).expanduser()
        if not p.is_absolute() and self._source_path is not None:
            p = self._source_path.parent / p
        return p

    def robot_model(self) -> str:
        """``robot.model``: a built-in name, or its URDF path resolved against the cell's folder."""
        model = self.robot.model
        if model.endswith((".urdf", ".xacro")):
            return str(self._relative_to_cell(model).resolve())
        return model

    def package_paths(self) -> list[Path]:
        """``robot.package_paths`` resolved against the cell file's folder."""
        return [self._relative_to_cell(p) for p in self.robot.package_paths]

    def build_robot(self) -> Arm:
        """The bare arm: model, base pose, limits and their scaling, the SRDF's disabled
        collision pairs (no tool, no obstacles)."""
        lim = self.robot.limits
        scaling = LimitScaling(lim.velocity_scale, lim.acceleration_scale, lim.jerk_scale)
        arm = Arm(
            self.robot_model(),
            T_cell_base=self.T_cell_base(),
            scaling=scaling,
            package_paths=self.package_paths(),
            position_limits=lim.position,
        )
        srdf = self.srdf()
        if srdf is not None and srdf.disabled:
            unknown = sorted({n for a, b, _ in srdf.disabled for n in (a, b)} - arm.link_names())
            if unknown:
                raise ConfigError(
                    srdf.path,
                    [
                        (
                            "disable_collisions",
                            unknown,
                            f"links not in the URDF {arm.urdf_path.name}",
                        )
                    ],
                )
            arm.set_disabled_pairs([(a, b) for a, b, _ in srdf.disabled])
        return arm

    def build_arm(self) -> Arm:
        """The arm with its base pose, limit scaling, tool and every obstacle attached."""
        arm = self.build_robot()
        arm.set_tool(self.T_tool0_tcp(), self.tool_shapes())
        arm.add_obstacles(self.obstacle_shapes())
        arm.set_clearance(self.robot.clearance_m, self.tool.clearance_m)
        return arm

    def part_material(self) -> tuple[Material, bool]:
        """The part's material and whether the cell file named it (False: steel assumed)."""
        m = self.part.material
        if m is None:
            return BUILTIN_MATERIALS[DEFAULT_MATERIAL], False
        return Material(m.name, m.alpha_per_K, m.u_alpha_per_K), True

    def calibration_path(self) -> Path | None:
        """The stereo calibration file, resolved against the cell file's folder."""
        if self.tool.calibration is None:
            return None
        path = Path(self.tool.calibration)
        if not path.is_absolute() and self._source_path is not None:
            path = self._source_path.parent / path
        return path
