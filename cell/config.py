"""The cell file (``cell.yaml``): robot, stereo head, part with holes, obstacles, reference targets.

Every length is in metres, every angle in radians. Poses are
``{xyz: [...], rpy: [...]}`` or ``{xyz: [...], quat_xyzw: [...]}``. The part's
holes and obstacles are given in the part frame, placed in the cell by
``part.base``; environment obstacles and reference targets are in the cell
frame. :func:`load_cell` validates the whole file and reports every problem
with the file name, the field path and the value.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Any

import numpy as np
import yaml
from pydantic import BaseModel, ConfigDict, Field, PrivateAttr, ValidationError, field_validator

from cell.config_checks import cell_problems
from cell.config_mesh import MeshSpec
from cell.config_target import CalibrationTargetBoard
from cell.errors import NO_VALUE, ConfigError
from cell.gdt.datums import Alignment, Datum, Tolerances, gdt_problems
from cell.holes_csv import read_holes_csv
from cell.uncertainty.materials import (
    BUILTIN_MATERIALS,
    DEFAULT_MATERIAL,
    Material,
    MaterialSpec,
    material_field,
)
from cell.yaml_problem import yaml_problem
from robots import DEFAULT_MODEL, Arm, LimitScaling, Shape
from robots.transforms import pose_to_matrix

DATA_DIR = Path(__file__).parent / "data"
BUILTIN_CELLS = ("motorcycle_frame",)
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


def _unit(v: list[float]) -> list[float]:
    n = float(np.linalg.norm(v))
    if n == 0.0 or not np.isfinite(n):
        raise ValueError("normal must be a non-zero vector")
    if abs(n - 1.0) > UNIT_TOL:
        raise ValueError(f"normal must have unit length (length {n:.6g})")
    return [float(x) / n for x in v]


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
    ``mesh`` (:mod:`cell.config_mesh`)."""

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
    home: Annotated[list[float], Field(min_length=6, max_length=6)]
    limits: Limits = Limits()
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
    #: GD&T position and size tolerances (:mod:`cell.gdt.datums`, docs/gdt.md)
    tolerances: Tolerances | None = None

    _unit_normal = field_validator("normal")(lambda cls, v: _unit(v))


#: plausible part temperatures (degC): outside, the figure is a mistake (kelvin, a typo)
PART_TEMPERATURE_RANGE_C = (-10.0, 50.0)


class Part(_Strict):
    base: Pose = IDENTITY
    holes: list[Hole] = []
    #: more holes from a CSV, relative to the cell file (:mod:`cell.holes_csv`)
    holes_csv: str | None = None
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
    #: datum features in precedence and the run's alignment (:mod:`cell.gdt.datums`)
    datums: list[Datum] = []
    alignment: Alignment | None = None

    _material = field_validator("material", mode="before")(lambda cls, v: material_field(v))


class Environment(_Strict):
    obstacles: list[ShapeSpec] = []


class ReferenceTarget(_Strict):
    id: Annotated[str, Field(min_length=1)]
    position: Vec3
    normal: Vec3
    diameter: Positive

    _unit_normal = field_validator("normal")(lambda cls, v: _unit(v))


class CalibrationTarget(CalibrationTargetBoard):
    """``calibration_target``: the plate board (:mod:`cell.config_target`) and its nominal
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

    _source_path: Path | None = PrivateAttr(default=None)
    _raw_text: str = PrivateAttr(default="")

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
        """The home joint vector (rad)."""
        return np.array(self.robot.home, dtype=float)

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
        """The bare arm: model, base pose, limits and their scaling (no tool, no obstacles)."""
        lim = self.robot.limits
        scaling = LimitScaling(lim.velocity_scale, lim.acceleration_scale, lim.jerk_scale)
        return Arm(
            self.robot_model(),
            T_cell_base=self.T_cell_base(),
            scaling=scaling,
            package_paths=self.package_paths(),
            position_limits=lim.position,
        )

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


def _field_path(loc: tuple[Any, ...]) -> str:
    out = ""
    for part in loc:
        if isinstance(part, int):
            out += f"[{part}]"
        elif part in ("function-after[_unit(), list[float]]",):
            continue
        else:
            out += f".{part}" if out else str(part)
    return out or "(top level)"


def _pydantic_problems(exc: ValidationError) -> list[tuple[str, object, str]]:
    problems = []
    for err in exc.errors():
        msg = err["msg"].removeprefix("Value error, ")
        if err["type"] == "extra_forbidden":
            msg = "unknown key"
        if err["type"] == "missing":  # pydantic's input is then the mapping around the key
            msg, err["input"] = "a required key is missing", NO_VALUE
        problems.append((_field_path(err["loc"]), err.get("input"), msg))
    return problems


def _with_csv_holes(
    cfg: CellConfig, source: str, source_path: Path | None, text: str
) -> CellConfig:
    """The cell with the holes of ``part.holes_csv`` appended to ``part.holes``."""
    csv_path = Path(cfg.part.holes_csv or "")
    if not csv_path.is_absolute() and cfg.base_dir is not None:
        csv_path = cfg.base_dir / csv_path
    rows = read_holes_csv(csv_path)
    seen = {h.id for h in cfg.part.holes}
    for n, row in enumerate(rows, start=2):
        if row["id"] in seen:
            raise ConfigError(str(csv_path), [(f"row {n}, column 'id'", row["id"], "duplicate id")])
        seen.add(str(row["id"]))
    try:
        extra = [Hole.model_validate(r) for r in rows]
    except ValidationError as exc:
        raise ConfigError(str(csv_path), _pydantic_problems(exc)) from exc
    part = cfg.part.model_copy(update={"holes": [*cfg.part.holes, *extra]})
    out = cfg.model_copy(update={"part": part})
    out._source_path = source_path
    out._raw_text = text
    return out


def parse_cell(text: str, source: str = "<cell>", source_path: Path | None = None) -> CellConfig:
    """Validate a cell file's YAML text; raises :class:`ConfigError` listing every problem."""
    try:
        data = yaml.safe_load(text)
    except yaml.YAMLError as exc:
        raise ConfigError(source, [yaml_problem(exc)]) from None
    if not isinstance(data, dict):
        raise ConfigError(source, [("(top level)", data, "a cell file is a mapping of keys")])
    try:
        cfg = CellConfig.model_validate(data)
    except ValidationError as exc:
        raise ConfigError(source, _pydantic_problems(exc)) from exc
    cfg._source_path = source_path
    cfg._raw_text = text
    if cfg.part.holes_csv is not None:
        cfg = _with_csv_holes(cfg, source, source_path, text)
    problems = gdt_problems(cfg) or cell_problems(cfg)
    if problems:
        raise ConfigError(source, problems)
    return cfg


def builtin_cell_path(name: str = "motorcycle_frame") -> Path:
    """Path of a cell file shipped with the package."""
    if name not in BUILTIN_CELLS:
        raise ConfigError(
            name, [("(name)", name, f"no built-in cell (known: {', '.join(BUILTIN_CELLS)})")]
        )
    return DATA_DIR / f"{name}.yaml"


def load_cell(path: str | Path | None = None) -> CellConfig:
    """Read and validate a cell file; ``None`` or a built-in name gives a built-in cell."""
    if path is None or str(path) in BUILTIN_CELLS:
        path = builtin_cell_path(str(path) if path else "motorcycle_frame")
    path = Path(path)
    if path.is_dir():
        raise ConfigError(str(path), [("(file)", str(path), "is a directory, not a cell file")])
    if not path.is_file():
        raise ConfigError(str(path), [("(file)", str(path), "no such file")])
    try:
        text = path.read_text(encoding="utf-8")
    except (UnicodeDecodeError, PermissionError) as exc:
        raise ConfigError(
            str(path), [("(file)", str(path), f"cannot be read as UTF-8 text: {exc}")]
        ) from exc
    return parse_cell(text, str(path), path.resolve())


def load_builtin_cell(name: str = "motorcycle_frame") -> CellConfig:
    """The built-in cell ``name``."""
    return load_cell(builtin_cell_path(name))
