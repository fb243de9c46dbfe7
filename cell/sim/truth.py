"""The simulated cell's hidden errors, written down: :class:`CellTruth` and ``truth.yaml``.

A truth fixes every error the simulated cell has and the runner never sees:

- ``dh_errors``: per joint ``(a_m, d_m, alpha_rad, theta_rad)`` added to the arm's nominal
  D-H rows (``theta_rad`` adds to the joint offset, i.e. it is the joint's zero error);
- ``base_error``, ``tcp_error``: poses composed onto the nominal ones,
  ``T_cell_base_true = T_cell_base @ base_error``, ``T_tool0_tcp_true = T_tool0_tcp @ tcp_error``;
- ``part_placement_error``: ``T_cell_part_true = T_cell_part @ part_placement_error`` (the part
  on its fixture; the true holes move with it);
- ``target_placement_error``: ``T_cell_target_true = T_cell_target @ target_placement_error``;
- ``hole_position_sigma_m``, ``hole_diameter_sigma_m``: the part as machined (per hole, drawn
  by the world from ``seed``);
- ``repeatability_rp_m``: the arm's ISO 9283 RP; ``calibration_sigma_scale``: how far the true
  stereo head is off its calibration file, in its stated sigmas; ``part_temperature_c``;
- ``marker_position_sigma_m``, ``marker_errors``: each reference marker off its nominal by a
  seeded N(0, sigma) per axis, or by its given offset (m; markers on the part move with the
  part's placement); each scale bar's true length off its ``length_m`` by N(0, U/2);
- ``seed``: every draw of the world (part, noise, head) and of the left-out fields.

**The realistic draw** (:meth:`CellTruth.drawn`, and every field a truth file leaves out)
depends on the seed only. Each signed error is ``sign * U(lo, hi)`` with a fair random sign:

| field | distribution |
|---|---|
| D-H ``a_m``, ``d_m`` (each joint) | ``U(0.2, 0.5) mm`` |
| D-H ``alpha_rad``, ``theta_rad`` (each joint) | ``U(0.01, 0.03) deg`` |
| ``tcp_error`` (the head on the flange) | ``1 mm * U(0.5, 1.5)``, ``0.3 deg * U(0.5, 1.5)`` |
| ``base_error`` | ``1 mm * U(0.5, 1.5)``, ``0.05 deg * U(0.5, 1.5)`` |
| ``part_placement_error`` | ``0.3 mm * U(0.5, 1.5)``, ``0.05 deg * U(0.5, 1.5)`` |
| ``target_placement_error`` | ``1 mm * U(0.5, 1.5)``, ``0.3 deg * U(0.5, 1.5)`` |
| ``hole_position_sigma_m``, ``hole_diameter_sigma_m`` | 15 um, 5 um (fixed) |
| ``marker_position_sigma_m`` | 0.3 mm (fixed): markers stuck on by hand |
| ``repeatability_rp_m`` | the data-sheet RP of the cell's robot (fixed) |
| ``calibration_sigma_scale`` | 1 (fixed) |
| ``part_temperature_c`` | ``U(20, 26) degC`` |

A pose error's translation and rotation vector each point in a uniformly random direction with
the magnitude shown. :meth:`CellTruth.zero` has no geometric error, no scatter, the head as
calibrated, a part at 20 degC, the part as machined as above (15 um, 5 um): the simulator's
world before truth files existed.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np
import yaml
from scipy.spatial.transform import Rotation

from cell.config import CellConfig
from cell.errors import TruthFileError
from cell.sim.truth_file import FORMAT, FORMAT_VERSION, TruthSpec, read_truth_spec
from cell.uncertainty.repeatability import repeatability_rp_m
from robots import DEFAULT_MODEL
from robots.dh import DHTable
from robots.transforms import make_transform, matrix_to_rpy

DH_KEYS = ("a_m", "d_m", "alpha_rad", "theta_rad")
#: (translation m, rotation rad) of each drawn pose error
POSE_ERROR_SIZES = {
    "base_error": (1e-3, np.radians(0.05)),
    "tcp_error": (1e-3, np.radians(0.3)),
    "part_placement_error": (0.3e-3, np.radians(0.05)),
    "target_placement_error": (1e-3, np.radians(0.3)),
}
DH_LENGTH_RANGE_M = (0.2e-3, 0.5e-3)
DH_ANGLE_RANGE_RAD = (np.radians(0.01), np.radians(0.03))
PART_TEMPERATURE_DRAW_C = (20.0, 26.0)
HOLE_POSITION_SIGMA_M = 15e-6
HOLE_DIAMETER_SIGMA_M = 5e-6
MARKER_POSITION_SIGMA_M = 3e-4
_STREAM = {
    "dh": 1,
    "base_error": 2,
    "tcp_error": 3,
    "part_placement_error": 4,
    "target_placement_error": 5,
    "temperature": 6,
}


@dataclass(frozen=True, eq=False)
class CellTruth:
    """Every hidden error of one simulated cell (m, rad, degC); see the module docstring.

    Attributes:
        seed: seed of every draw of the world and of the drawn fields.
        dh_errors: (6, 4) array, per joint ``a_m, d_m, alpha_rad, theta_rad`` added to the
            nominal D-H row.
        base_error, tcp_error, part_placement_error, target_placement_error: 4x4 poses,
            composed on the right of the nominal ones.
    """

    seed: int
    dh_errors: np.ndarray
    base_error: np.ndarray
    tcp_error: np.ndarray
    part_placement_error: np.ndarray
    target_placement_error: np.ndarray
    hole_position_sigma_m: float
    hole_diameter_sigma_m: float
    repeatability_rp_m: float
    calibration_sigma_scale: float
    part_temperature_c: float
    marker_position_sigma_m: float = MARKER_POSITION_SIGMA_M
    marker_errors: dict[str, tuple[float, float, float]] = field(default_factory=dict)

    def __post_init__(self) -> None:
        """Shapes and finiteness checked; the arrays are copied read-only."""
        shapes = {"dh_errors": (6, 4), "base_error": (4, 4), "tcp_error": (4, 4),
                  "part_placement_error": (4, 4), "target_placement_error": (4, 4)}  # fmt: skip
        for name, shape in shapes.items():
            a = np.array(getattr(self, name), dtype=float)
            if a.shape != shape or not np.all(np.isfinite(a)):
                raise TruthFileError("CellTruth", [(name, a.shape, f"need finite {shape}")])
            a.setflags(write=False)
            object.__setattr__(self, name, a)

    @staticmethod
    def zero(seed: int = 0) -> CellTruth:
        """No geometric error, no scatter, the head as calibrated, the part at 20 degC."""
        return CellTruth(
            int(seed),
            np.zeros((6, 4)),
            np.eye(4),
            np.eye(4),
            np.eye(4),
            np.eye(4),
            HOLE_POSITION_SIGMA_M,
            HOLE_DIAMETER_SIGMA_M,
            0.0,
            0.0,
            20.0,
        )

    @staticmethod
    def drawn(seed: int, cell: CellConfig | None = None) -> CellTruth:
        """The realistic draw of ``seed`` (the module docstring's table); ``cell`` gives the
        robot whose data-sheet repeatability is used (None: the default model's)."""
        seed = int(seed)
        rng = np.random.default_rng([seed, _STREAM["dh"]])
        lo, hi = np.array(
            [DH_LENGTH_RANGE_M, DH_LENGTH_RANGE_M, DH_ANGLE_RANGE_RAD, DH_ANGLE_RANGE_RAD]
        ).T
        dh = _signed(rng, lo, hi, (6, 4))
        poses = {
            k: _pose_error(np.random.default_rng([seed, _STREAM[k]]), *size)
            for k, size in POSE_ERROR_SIZES.items()
        }
        t_rng = np.random.default_rng([seed, _STREAM["temperature"]])
        model, figure = (
            (DEFAULT_MODEL, None)
            if cell is None
            else (cell.robot.model, cell.robot.repeatability_m)
        )
        rp, _ = repeatability_rp_m(model, figure)
        return CellTruth(
            seed,
            dh,
            **poses,
            hole_position_sigma_m=HOLE_POSITION_SIGMA_M,
            hole_diameter_sigma_m=HOLE_DIAMETER_SIGMA_M,
            repeatability_rp_m=rp,
            calibration_sigma_scale=1.0,
            part_temperature_c=float(t_rng.uniform(*PART_TEMPERATURE_DRAW_C)),
        )

    @staticmethod
    def load(path: str | Path, cell: CellConfig | None = None, seed: int = 0) -> CellTruth:
        """A truth file: its fields over the realistic draw of its ``seed`` (``seed`` here when
        the file has none). Raises :class:`cell.errors.TruthFileError` naming the field."""
        return from_spec(read_truth_spec(path), cell, seed)

    def table(self, nominal: DHTable) -> DHTable:
        """The true D-H table: ``nominal`` plus :attr:`dh_errors` (no thermal drift)."""
        a, d, alpha, theta = nominal.arrays()
        e = self.dh_errors
        return replace(
            nominal,
            a_m=tuple(map(float, a + e[:, 0])),
            d_m=tuple(map(float, d + e[:, 1])),
            alpha_rad=tuple(map(float, alpha + e[:, 2])),
            theta_offset_rad=tuple(map(float, theta + e[:, 3])),
        )

    def is_geometrically_zero(self) -> bool:
        """No D-H, base, head, part or target error."""
        eye = np.eye(4)
        poses = (
            self.base_error,
            self.tcp_error,
            self.part_placement_error,
            self.target_placement_error,
        )
        return not np.any(self.dh_errors) and all(np.array_equal(T, eye) for T in poses)

    def to_dict(self) -> dict:
        """The truth file's content (every field written)."""
        return {
            "format": FORMAT,
            "version": FORMAT_VERSION,
            "seed": self.seed,
            "robot": {
                "dh_errors": [
                    dict(zip(DH_KEYS, map(float, row), strict=True)) for row in self.dh_errors
                ],
                "base_error": _pose_dict(self.base_error),
                "repeatability_rp_m": float(self.repeatability_rp_m),
            },
            "tool": {"tcp_error": _pose_dict(self.tcp_error)},
            "part": {
                "placement_error": _pose_dict(self.part_placement_error),
                "hole_position_sigma_m": float(self.hole_position_sigma_m),
                "hole_diameter_sigma_m": float(self.hole_diameter_sigma_m),
                "temperature_c": float(self.part_temperature_c),
            },
            "calibration_target": {"placement_error": _pose_dict(self.target_placement_error)},
            "stereo": {"calibration_sigma_scale": float(self.calibration_sigma_scale)},
            "reference_markers": {
                "position_error_sigma_m": float(self.marker_position_sigma_m),
                "errors": {k: [float(v) for v in e] for k, e in self.marker_errors.items()},
            },
        }

    def to_yaml(self) -> str:
        """The truth file's YAML text (reads back with :meth:`load` to the same truth)."""
        return yaml.safe_dump(self.to_dict(), sort_keys=False, default_flow_style=None)


def from_spec(spec: TruthSpec, cell: CellConfig | None = None, seed: int = 0) -> CellTruth:
    """A validated truth file's fields over the realistic draw of its seed."""
    base = CellTruth.drawn(spec.seed if spec.seed is not None else seed, cell)
    dh = base.dh_errors.copy()
    for j, row in enumerate(spec.robot.dh_errors or ()):
        for k, key in enumerate(DH_KEYS):
            v = getattr(row, key)
            if v is not None:
                dh[j, k] = v
    poses = {
        "base_error": spec.robot.base_error,
        "tcp_error": spec.tool.tcp_error,
        "part_placement_error": spec.part.placement_error,
        "target_placement_error": spec.calibration_target.placement_error,
    }
    given = {k: p.matrix() for k, p in poses.items() if p is not None}
    scalars = {
        "hole_position_sigma_m": spec.part.hole_position_sigma_m,
        "hole_diameter_sigma_m": spec.part.hole_diameter_sigma_m,
        "part_temperature_c": spec.part.temperature_c,
        "repeatability_rp_m": spec.robot.repeatability_rp_m,
        "calibration_sigma_scale": spec.stereo.calibration_sigma_scale,
    }
    given |= {k: float(v) for k, v in scalars.items() if v is not None}
    rm = spec.reference_markers
    if rm.position_error_sigma_m is not None:
        given["marker_position_sigma_m"] = float(rm.position_error_sigma_m)
    if rm.errors and cell is not None:
        known = {m.id for m in cell.reference_markers}
        bad = [(f"reference_markers.errors.{k}", k, "names no reference marker of the cell")
               for k in rm.errors if k not in known]  # fmt: skip
        if bad:
            raise TruthFileError("truth file", bad)
    if rm.errors:
        given["marker_errors"] = {k: tuple(float(x) for x in v) for k, v in rm.errors.items()}
    return replace(base, dh_errors=dh, **given)


def _signed(rng: np.random.Generator, lo: np.ndarray, hi: np.ndarray, shape) -> np.ndarray:
    """``sign * U(lo, hi)`` with a fair random sign."""
    mag = rng.uniform(0.0, 1.0, shape) * (hi - lo) + lo
    return np.where(rng.uniform(0.0, 1.0, shape) < 0.5, -mag, mag)


def _pose_error(rng: np.random.Generator, size_m: float, size_rad: float) -> np.ndarray:
    """A pose error: translation and rotation vector in random directions, magnitudes
    ``size * U(0.5, 1.5)``."""
    t = _direction(rng) * size_m * rng.uniform(0.5, 1.5)
    r = _direction(rng) * size_rad * rng.uniform(0.5, 1.5)
    return make_transform(Rotation.from_rotvec(r).as_matrix(), t)


def _direction(rng: np.random.Generator) -> np.ndarray:
    v = rng.normal(0.0, 1.0, 3)
    return v / np.linalg.norm(v)


def _pose_dict(T: np.ndarray) -> dict[str, list[float]]:
    return {
        "xyz": [float(v) for v in T[:3, 3]],
        "rpy": [float(v) for v in matrix_to_rpy(T[:3, :3])],
    }
