"""The schema of a simulated-truth file (``truth.yaml``), validated field by field.

Every field is optional: :mod:`cell.sim.truth` draws the ones left out. Unknown keys,
non-finite values, poses without a rotation and figures too large to be a realistic error
(mostly a unit mistake: millimetres for metres, degrees for radians) are refused with the
field's path. Lengths in m, angles in rad, temperatures in degC.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any, Literal

import yaml
from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator

from cell.config import PART_TEMPERATURE_RANGE_C, Pose
from cell.config.problems import pydantic_problems
from cell.config.yaml_problem import yaml_problem
from cell.errors import NO_VALUE, TruthFileError

#: the truth file's format tag and version (optional in a file; written first)
FORMAT = "holecell.truth"
FORMAT_VERSION = 1
#: the tag of files written before format + version (still read)
LEGACY_FORMAT = "holecell.truth/1"
#: largest D-H length error (m) and angle error (rad) a truth file may state
MAX_DH_LENGTH_ERROR_M = 0.01
MAX_DH_ANGLE_ERROR_RAD = 0.05
#: rows of ``robot.dh_errors``: one per joint
DH_ROWS = 6
#: a value whose repr is longer is shortened in a refusal (one line)
MAX_VALUE_CHARS = 60
#: largest translation (m, per axis) and rotation (rad, per rpy angle) of a pose error
MAX_POSE_ERROR_M = 0.05
MAX_POSE_ERROR_RAD = 0.1

DHLength = Annotated[float, Field(ge=-MAX_DH_LENGTH_ERROR_M, le=MAX_DH_LENGTH_ERROR_M)]
DHAngle = Annotated[float, Field(ge=-MAX_DH_ANGLE_ERROR_RAD, le=MAX_DH_ANGLE_ERROR_RAD)]
Sigma = Annotated[float, Field(ge=0, le=1e-3)]


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)


class ErrorPose(Pose):
    """A pose error: small (``MAX_POSE_ERROR_M`` per axis, ``MAX_POSE_ERROR_RAD`` per angle)."""

    @field_validator("xyz")
    @classmethod
    def _small_xyz(cls, v: list[float]) -> list[float]:
        if any(abs(x) > MAX_POSE_ERROR_M for x in v):
            raise ValueError(f"a pose error's xyz must be within +-{MAX_POSE_ERROR_M} m per axis")
        return v

    @field_validator("rpy")
    @classmethod
    def _small_rpy(cls, v: list[float] | None) -> list[float] | None:
        if v is not None and any(abs(x) > MAX_POSE_ERROR_RAD for x in v):
            raise ValueError(f"a pose error's rpy must be within +-{MAX_POSE_ERROR_RAD} rad")
        return v


class DHErrorSpec(_Strict):
    a_m: DHLength | None = None
    d_m: DHLength | None = None
    alpha_rad: DHAngle | None = None
    theta_rad: DHAngle | None = None


class RobotTruth(_Strict):
    dh_errors: (
        Annotated[list[DHErrorSpec], Field(min_length=DH_ROWS, max_length=DH_ROWS)] | None
    ) = None
    base_error: ErrorPose | None = None
    repeatability_rp_m: Sigma | None = None


class ToolTruth(_Strict):
    tcp_error: ErrorPose | None = None


class PartTruth(_Strict):
    placement_error: ErrorPose | None = None
    hole_position_sigma_m: Sigma | None = None
    hole_diameter_sigma_m: Sigma | None = None
    temperature_c: (
        Annotated[float, Field(ge=PART_TEMPERATURE_RANGE_C[0], le=PART_TEMPERATURE_RANGE_C[1])]
        | None
    ) = None


class TargetTruth(_Strict):
    placement_error: ErrorPose | None = None


class StereoTruth(_Strict):
    calibration_sigma_scale: Annotated[float, Field(ge=0, le=10)] | None = None


class MarkersTruth(_Strict):
    position_error_sigma_m: Sigma | None = None
    errors: dict[str, Annotated[list[float], Field(min_length=3, max_length=3)]] = {}


class TruthSpec(_Strict):
    """A whole truth file (every key optional)."""

    format: Literal["holecell.truth", "holecell.truth/1"] | None = None
    version: Literal[1] | None = None
    seed: Annotated[int, Field(ge=0, lt=2**63)] | None = None
    robot: RobotTruth = RobotTruth()
    tool: ToolTruth = ToolTruth()
    part: PartTruth = PartTruth()
    calibration_target: TargetTruth = TargetTruth()
    stereo: StereoTruth = StereoTruth()
    reference_markers: MarkersTruth = MarkersTruth()


class _Short(str):
    """A long value's repr cut to :data:`MAX_VALUE_CHARS` (shown as is in a refusal)."""

    def __repr__(self) -> str:
        return str(self)


def _shown(value: object) -> object:
    text = repr(value)
    return value if len(text) <= MAX_VALUE_CHARS else _Short(text[: MAX_VALUE_CHARS - 3] + "...")


def _problems(exc: ValidationError, prefix: tuple[Any, ...] = ()) -> list[tuple[str, object, str]]:
    return pydantic_problems(exc, prefix, _shown)


def _dh_rows(data: dict[str, Any]) -> list[Any] | None:
    robot = data.get("robot")
    rows = robot.get("dh_errors") if isinstance(robot, dict) else None
    return rows if isinstance(rows, list) else None


def _dh_count_problems(rows: list[Any]) -> list[tuple[str, object, str]]:
    """A ``dh_errors`` list of the wrong length: the count, and each row's own problems
    (pydantic stops at the length and would not name an unknown key inside a row)."""
    out: list[tuple[str, object, str]] = [
        ("robot.dh_errors", NO_VALUE, f"{len(rows)} rows: one per joint, {DH_ROWS} rows expected")
    ]
    for i, row in enumerate(rows):
        try:
            DHErrorSpec.model_validate(row)
        except ValidationError as exc:
            out += _problems(exc, ("robot", "dh_errors", i))
    return out


def parse_truth_spec(text: str, source: str) -> TruthSpec:
    """Validate a truth file's YAML text; raises :class:`TruthFileError` naming each field
    (one line each; a YAML syntax error with its line and column)."""
    try:
        data = yaml.safe_load(text)
    except yaml.YAMLError as exc:
        raise TruthFileError(source, [yaml_problem(exc)]) from None
    if data is None:
        data = {}
    if not isinstance(data, dict):
        raise TruthFileError(
            source, [("(top level)", _shown(data), "a truth file is a mapping of keys")]
        )
    try:
        return TruthSpec.model_validate(data)
    except ValidationError as exc:
        problems = _problems(exc)
        rows = _dh_rows(data)
        if rows is not None and len(rows) != DH_ROWS:
            problems = [p for p in problems if p[0] != "robot.dh_errors"]
            problems = _dh_count_problems(rows) + problems
        raise TruthFileError(source, problems) from None


def read_truth_spec(path: str | Path) -> TruthSpec:
    """Read and validate the truth file at ``path``."""
    p = Path(path)
    if p.is_dir():
        raise TruthFileError(str(p), [("(file)", str(p), "is a directory, not a truth file")])
    if not p.is_file():
        raise TruthFileError(str(p), [("(file)", str(p), "no such file")])
    try:
        text = p.read_text(encoding="utf-8")
    except (UnicodeDecodeError, PermissionError) as exc:
        raise TruthFileError(str(p), [("(file)", str(p), f"cannot be read: {exc}")]) from exc
    return parse_truth_spec(text, str(p))
