"""The cell calibration a run uses (``holecell run --calibration cellcal.json``).

:func:`load_run_calibration` reads ``cellcal.json`` and refuses, in one line naming the file
and field, a file of another robot, tool, cell or stereo calibration (the fingerprints of
:mod:`cell.calibration.file.provenance` computed from the run's cell file) or one older than
``max_age_days`` (:data:`MAX_AGE_DAYS`, 7 days by default). :func:`store_calibration` copies it
into the run directory (``RUN_DIR/cellcal.json``) so a resumed run and the report use the same
one; a resumed run reads that copy and checks it against the stored cell again (not its age:
it continues the run it started).

:class:`RunGeometry` is the run's kinematics, with or without a calibration: the D-H table
(calibrated: nominal plus the file's errors; the thermal model identifies on top of it), the
base in the cell and the TCP on the flange, and the forward kinematics ``fk(q, "tcp")``
(``T_cell_tcp``). With a calibration:

- ``T_tool0_tcp = T_tool0_camera @ head_frame(stereo)``: the calibrated hand-eye carried from
  the left camera to the head frame (the TCP);
- ``T_cell_base``: ``base_from="cell"`` (default) keeps the cell file's ``robot.base``;
  ``"target"`` takes ``T_cell_target @ inv(T_base_target)`` (the plate's pose in the cell file
  taken as surveyed). The calibration sees the base only through the plate, so the second is
  better only where the plate's pose in the cell is known better than the robot's base.
"""

from __future__ import annotations

import shutil
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from cell.calibration.errors import CalibrationFileError
from cell.calibration.estimate.result import CellCalibration
from cell.calibration.file.modelfile import check_age, check_belongs, load_calibration
from cell.calibration.file.provenance import cell_provenance
from cell.calibration.use.apply import CalibratedKinematics
from cell.config import CellConfig
from measure import StereoCalibration, head_frame
from robots import Arm
from robots.dh import DHTable, fk_dh
from robots.transforms import invert

Array = NDArray[np.float64]

#: a run refuses a calibration older than this (days) unless ``--calibration-max-age`` says
#: otherwise: a week is how long a production cell runs between re-checks of the arm's
#: geometry and the head's mount (a crash, a head change or a new base void it at once)
MAX_AGE_DAYS = 7.0
#: the copy of the calibration in the run directory
RUN_FILENAME = "cellcal.json"
BASE_FROM = ("cell", "target")


@dataclass(frozen=True)
class RunCalibration:
    """A checked calibration and where it came from (``source``: the file given)."""

    calibration: CellCalibration
    kinematics: CalibratedKinematics
    source: str

    def info(self, now: datetime | None = None) -> dict[str, Any]:
        """The report's fields: file, date, age (days), key one-sigma figures (m, rad)."""
        cal = self.calibration
        made = datetime.strptime(cal.created_utc, "%Y-%m-%dT%H:%M:%SZ").replace(tzinfo=UTC)
        age = ((now or datetime.now(UTC)) - made).total_seconds() / 86400.0
        he = cal.T_tool0_camera
        free = [t for t in cal.dh_terms if t.free]
        return {
            "file": self.source,
            "created_utc": cal.created_utc,
            "age_days": age,
            "sigma_hand_eye_xyz_m": [float(v) for v in he.sigma_xyz_m],
            "sigma_hand_eye_rot_rad": [float(v) for v in he.sigma_rot_rad],
            "dh_terms_free": len(free),
            "dh_terms_fixed": len(cal.dh_terms) - len(free),
            "views": int(cal.counts.get("views", 0)),
            "residual_rms_px": dict(cal.residual_rms_px),
        }


def expected_provenance(cell: CellConfig, arm: Arm, stereo: StereoCalibration):
    """The fingerprints a calibration of this cell, arm and head carries."""
    return cell_provenance(cell, arm.dh, stereo.source, stereo.to_dict())


def load_run_calibration(
    path: str | Path,
    cell: CellConfig,
    arm: Arm,
    stereo: StereoCalibration,
    max_age_days: float | None = MAX_AGE_DAYS,
    now: datetime | None = None,
) -> RunCalibration:
    """Read and check ``cellcal.json`` for a run of ``cell`` (``max_age_days`` None: no age
    limit, a resumed run's own copy). Raises :class:`CalibrationFileError` naming the field."""
    src = str(path)
    cal = load_calibration(path)
    check_belongs(cal, expected_provenance(cell, arm, stereo), src)
    if max_age_days is not None:
        check_age(cal, max_age_days, now, src)
    if cal.nominal_dh is None:
        raise CalibrationFileError(
            src, "dh.nominal", "null: a run needs a calibration with the arm's joints "
            "(holecell calibrate cell, or calibrate hand-eye with --cell)")  # fmt: skip
    return RunCalibration(cal, CalibratedKinematics(cal), src)


def store_calibration(run: RunCalibration, run_dir: str | Path) -> Path:
    """Copy the calibration's file into ``run_dir`` (a temporary file renamed): returns it.
    The copy is byte for byte the file given, so its fingerprints and date stay as checked."""
    dest = Path(run_dir) / RUN_FILENAME
    if Path(run.source).resolve() == dest.resolve():
        return dest
    tmp = dest.with_name(dest.name + ".tmp")
    shutil.copyfile(run.source, tmp)
    tmp.replace(dest)
    return dest


def stored_calibration_path(run_dir: str | Path) -> Path | None:
    """``RUN_DIR/cellcal.json`` if the run stored one."""
    p = Path(run_dir) / RUN_FILENAME
    return p if p.exists() else None


def calibrated_stereo(
    stereo: StereoCalibration, run_cal: RunCalibration | None
) -> StereoCalibration:
    """The head a run triangulates with: ``stereo`` (the file's intrinsics and uncertainty)
    with the calibration's stereo extrinsics ``T_left_right`` when it estimated them (the
    plate's known geometry fixes them in the cell, with the arm as it is); ``stereo`` itself
    otherwise."""
    if run_cal is None or run_cal.calibration.T_left_right is None:
        return stereo
    T_right_left = invert(run_cal.calibration.T_left_right.T)
    return StereoCalibration(stereo.image_size, stereo.K_left, stereo.dist_left, stereo.K_right,
                             stereo.dist_right, T_right_left[:3, :3].copy(),
                             T_right_left[:3, 3].copy(), source=stereo.source,
                             uncertainty=stereo.uncertainty)  # fmt: skip


class RunGeometry:
    """The kinematics a run measures and commands with (see the module docstring).

    Duck-types the parts of :class:`robots.Arm` the measurement and the thermal update use:
    ``dh``, ``T_cell_base``, ``T_tool0_tcp`` and ``fk(q, frame)``.
    """

    def __init__(
        self,
        arm: Arm,
        stereo: StereoCalibration,
        run_cal: RunCalibration | None = None,
        T_cell_target: Array | None = None,
        base_from: str = "cell",
    ) -> None:
        if base_from not in BASE_FROM:
            raise ValueError(f"base_from must be one of {BASE_FROM}, got {base_from!r}")
        self.run_calibration = run_cal
        self.base_from = base_from
        if run_cal is None:
            self.dh: DHTable = arm.dh
            self.T_cell_base: Array = np.asarray(arm.T_cell_base, float)
            self.T_tool0_tcp: Array = np.asarray(arm.T_tool0_tcp, float)
            return
        kin = run_cal.kinematics
        self.dh = kin.dh_table
        self.T_tool0_tcp = kin.T_tool0_camera @ head_frame(stereo)
        if base_from == "target":
            if T_cell_target is None:
                raise ValueError("base_from='target' needs the cell file's calibration_target")
            Y = run_cal.calibration.T_base_target.T
            self.T_cell_base = np.asarray(T_cell_target, float) @ invert(Y)
        else:
            self.T_cell_base = np.asarray(arm.T_cell_base, float)

    @property
    def calibrated(self) -> bool:
        """True when a calibration is applied."""
        return self.run_calibration is not None

    def fk(self, q: Any, frame: str = "tcp") -> Array:
        """``T_cell_tcp`` (``frame="tcp"``) or ``T_cell_tool0`` of joints ``q`` (rad)."""
        if frame not in ("tcp", "tool0"):
            raise ValueError(f"frame must be 'tcp' or 'tool0', got {frame!r}")
        T = self.T_cell_base @ fk_dh(self.dh, q)
        return T @ self.T_tool0_tcp if frame == "tcp" else T

    def point_factor_cell(self, q: Any, p_camera_m: Any) -> Array | None:
        """``A`` (3, p), cell frame axes (m per unit normal): the error a point fixed in the
        left camera's frame at joints ``q`` takes from the calibration's uncertainty is
        ``A z`` with ``z ~ N(0, I_p)`` shared by every point of the run (one calibration for
        the whole run); its covariance is ``A A^T``. None without a calibration.

        Relative to the plate (``CalibratedKinematics.point_jacobian(frame="target")``:
        hand-eye, D-H terms and the plate's pose with their correlations): the calibration
        knows the head only against the plate, and ``base_link`` alone is a gauge. Much of the
        error is common to all holes of a part (a rigid motion): the shared ``z`` lets a
        datum alignment remove it (:mod:`cell.gdt.montecarlo`)."""
        if self.run_calibration is None:
            return None
        kin = self.run_calibration.kinematics
        J = kin.point_jacobian(q, p_camera_m, frame="target")
        R = self.T_cell_base[:3, :3] @ self.run_calibration.calibration.T_base_target.T[:3, :3]
        return R @ J @ kin.covariance_factor()

    def point_covariance_cell(self, q: Any, p_camera_m: Any) -> Array:
        """``A A^T`` of :meth:`point_factor_cell` (3, 3, m^2; zeros without a calibration)."""
        A = self.point_factor_cell(q, p_camera_m)
        return np.zeros((3, 3)) if A is None else A @ A.T


def calibration_summary(run_dir: str | Path, now: datetime | None = None) -> dict[str, Any] | None:
    """The report's ``calibration`` fields of the copy a run stored (None: the run used none;
    a copy that cannot be read any more says so in ``error``)."""
    path = stored_calibration_path(run_dir)
    if path is None:
        return None
    try:
        cal = load_calibration(path)
    except CalibrationFileError as exc:
        return {"file": str(path), "error": str(exc)}
    return RunCalibration(cal, CalibratedKinematics(cal), str(path)).info(now)


def describe(info: dict[str, Any] | None) -> str:
    """One line for people: file, date, age, the hand-eye's sigma (mm, deg)."""
    if info is None:
        return "none: the cell file's kinematics, base and head mount taken as exact"
    if "error" in info:
        return f"{info['file']}: {info['error']}"
    s_p = float(np.linalg.norm(info["sigma_hand_eye_xyz_m"]))
    s_r = float(np.degrees(np.linalg.norm(info["sigma_hand_eye_rot_rad"])))
    return (f"{info['file']}, made {info['created_utc']} ({info['age_days']:.1f} days before "
            f"the report); hand-eye sigma {s_p * 1e3:.4f} mm, {s_r:.4f} deg; "
            f"{info['views']} views, {info['dh_terms_free']} D-H terms estimated")  # fmt: skip
