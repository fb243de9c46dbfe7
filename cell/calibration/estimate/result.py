"""The cell calibration's estimates: what ``cellcal.json`` holds (:mod:`.modelfile`).

Pose covariances are 6x6 over ``(x, y, z)`` (m) and ``(rx, ry, rz)`` (rad): the position and a
small rotation vector in the parent frame, ``R = exp([r]) R_est`` (the perturbation of
:mod:`cell.calibration.estimate.model`). ``covariance`` is the joint covariance of every free
parameter, in ``parameter_names`` order, so correlations (hand-eye against D-H terms) are kept.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from robots.dh import DHTable

Array = NDArray[np.float64]

#: the version of the cellcal.json layout this code writes and reads
SCHEMA_VERSION = 1
FORMAT = "holecell.cellcal"


@dataclass(frozen=True, eq=False)
class PoseEstimate:
    """A pose ``T`` (4x4, m) and its 6x6 covariance (see the module docstring)."""

    T: Array
    covariance: Array

    @property
    def sigma_xyz_m(self) -> Array:
        """One-sigma position uncertainty per axis (m)."""
        return np.sqrt(np.diag(self.covariance)[:3])

    @property
    def sigma_rot_rad(self) -> Array:
        """One-sigma rotation uncertainty about each parent axis (rad)."""
        return np.sqrt(np.diag(self.covariance)[3:])


@dataclass(frozen=True)
class DHTermEstimate:
    """One D-H error term: value (m or rad), one sigma (0 when fixed), free or fixed and why."""

    name: str
    value: float
    sigma: float
    free: bool
    reason: str = ""


@dataclass(frozen=True)
class ViewResidual:
    """Reprojection RMS of one view (px) per camera (NaN where the camera did not see it)."""

    name: str
    rms_left_px: float
    rms_right_px: float
    n_points: int


@dataclass(frozen=True)
class Provenance:
    """What the calibration belongs to: robot model and fingerprints of the robot (model and
    nominal D-H table), the tool (the cell file's ``tool`` section) and the cell (its name and
    robot base), and the stereo calibration file used (path and a fingerprint of its content).
    ``None`` where unknown (offline data without a cell file)."""

    robot_model: str | None = None
    robot_fingerprint: str | None = None
    tool_fingerprint: str | None = None
    cell_fingerprint: str | None = None
    stereo_source: str | None = None
    stereo_fingerprint: str | None = None


@dataclass(frozen=True, eq=False)
class CellCalibration:
    """Every estimate of one calibration, its uncertainty and how well it fits.

    Attributes:
        T_tool0_camera: the left camera in ``tool0`` (the hand-eye).
        T_base_target: the target's plate frame in ``base_link``.
        T_left_right: the right camera in the left one (stereo heads; ``None`` for mono).
        nominal_dh: the nominal table the D-H errors add to (``None``: no kinematic terms).
        dh_terms: all 24 D-H error terms (free and fixed with reasons); empty without kinematics.
        parameter_names, covariance: the joint covariance of the free parameters (corner
            noise and the flange scatter, :mod:`cell.calibration.estimate.covariance`).
        sigma_px: ``s``, the estimated corner noise (px).
        flange_scatter: ``sigma_m``, ``sigma_rad`` (per axis) and ``source`` of the per-view
            flange pose error the covariance holds (:mod:`cell.calibration.estimate.covariance`).
        residual_rms_px: per camera ("left", "right").
        views: per-view residuals.
        counts: ``views``, ``points`` (corners), ``residuals``, ``parameters``, ``dof``.
        target: the board: ``kind``, ``cols``, ``rows``, ``pitch_m``.
        provenance, created_utc (ISO 8601), notes (free text lines: the method, warnings).
    """

    T_tool0_camera: PoseEstimate
    T_base_target: PoseEstimate
    T_left_right: PoseEstimate | None
    nominal_dh: DHTable | None
    dh_terms: tuple[DHTermEstimate, ...]
    parameter_names: tuple[str, ...]
    covariance: Array
    sigma_px: float
    residual_rms_px: dict[str, float]
    views: tuple[ViewResidual, ...]
    counts: dict[str, int]
    target: dict[str, object]
    provenance: Provenance = field(default_factory=Provenance)
    created_utc: str = ""
    notes: tuple[str, ...] = ()
    flange_scatter: dict[str, object] = field(default_factory=dict)

    @property
    def delta(self) -> Array:
        """The D-H error vector (24,) (zeros without kinematic terms)."""
        out = np.zeros(24)
        for k, t in enumerate(self.dh_terms):
            out[k] = t.value
        return out

    def sigma(self, name: str) -> float:
        """One sigma of a free parameter by name (``"T_tool0_camera.x_m"``, ``"dh.a2_m"``)."""
        k = self.parameter_names.index(name)
        return float(np.sqrt(self.covariance[k, k]))
