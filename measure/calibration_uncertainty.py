"""Standard uncertainties of a stereo calibration: the ``uncertainty`` block of ``stereo.json``.

``holecell calibrate`` fills it from OpenCV's extended calibration (per-parameter standard
deviations of each camera's intrinsics) and from the stereo solve (extrinsics); the uncertainty
budget of a hole (``cell``) propagates it through triangulation and the circle fit::

    "uncertainty": {
      "left":  {"K_std_px": [fx, fy, cx, cy], "dist_std": [k1, k2, p1, p2, k3]},
      "right": {"K_std_px": [...], "dist_std": [...]},
      "rvec_std_rad": [rx, ry, rz],     # rotation vector of R, left→right
      "T_std_m": [tx, ty, tz],
      "rms_px": 0.21,                   # stereo reprojection RMS
      "per_view_rms_px": [[left, right], ...],
      "method": "jacobian"              # optional: how the standard deviations were estimated
    }

Every figure is one standard deviation (GUM standard uncertainty), in the unit its name says.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from measure.calibration_fields import number_field
from measure.errors import CalibrationError


@dataclass(frozen=True, eq=False)
class CalibrationUncertainty:
    """One-sigma uncertainties of a :class:`measure.calibration.StereoCalibration`.

    Attributes:
        K_std_left_px, K_std_right_px: ``(fx, fy, cx, cy)`` standard deviations (pixels).
        dist_std_left, dist_std_right: ``(k1, k2, p1, p2, k3)`` standard deviations (unitless).
        rvec_std_rad: standard deviation of the left→right rotation vector (radians).
        T_std_m: standard deviation of the left→right translation (metres).
        rms_px: reprojection RMS of the stereo solve (pixels).
        per_view_rms_px: per view (image pair), the left and right reprojection RMS (pixels).
        method: how the standard deviations were estimated ("" when not said):
            ``"jacobian"`` (σ²(JᵀJ)⁻¹ at the solution, :mod:`measure.calibration_covariance`)
            or ``"max(jacobian, bootstrap over pairs xN)"``.
    """

    K_std_left_px: np.ndarray
    dist_std_left: np.ndarray
    K_std_right_px: np.ndarray
    dist_std_right: np.ndarray
    rvec_std_rad: np.ndarray
    T_std_m: np.ndarray
    rms_px: float
    per_view_rms_px: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))
    method: str = ""

    @classmethod
    def from_dict(cls, data: Any, source: str = "<memory>") -> CalibrationUncertainty:
        """Build from the ``uncertainty`` block; raise :class:`CalibrationError` on a bad field."""
        if not isinstance(data, dict):
            raise CalibrationError(source, "uncertainty", "must be an object")
        cams = {}
        for side in ("left", "right"):
            cam = data.get(side)
            if not isinstance(cam, dict):
                raise CalibrationError(source, f"uncertainty.{side}", "missing or not an object")
            cams[side] = (
                _std(cam, "K_std_px", 4, source, f"uncertainty.{side}."),
                _std(cam, "dist_std", 5, source, f"uncertainty.{side}."),
            )
        rms = _std(data, "rms_px", None, source, "uncertainty.")
        views = np.asarray(data.get("per_view_rms_px", []), dtype=np.float64).reshape(-1, 2)
        method = data.get("method", "")
        if not isinstance(method, str):
            raise CalibrationError(source, "uncertainty.method", f"must be text, got {method!r}")
        return cls(
            K_std_left_px=cams["left"][0],
            dist_std_left=cams["left"][1],
            K_std_right_px=cams["right"][0],
            dist_std_right=cams["right"][1],
            rvec_std_rad=_std(data, "rvec_std_rad", 3, source, "uncertainty."),
            T_std_m=_std(data, "T_std_m", 3, source, "uncertainty."),
            rms_px=float(rms),
            per_view_rms_px=views,
            method=method,
        )

    def to_dict(self) -> dict[str, Any]:
        """The ``uncertainty`` block of ``stereo.json`` (plain lists)."""
        out: dict[str, Any] = {
            "left": {
                "K_std_px": self.K_std_left_px.tolist(),
                "dist_std": self.dist_std_left.tolist(),
            },
            "right": {
                "K_std_px": self.K_std_right_px.tolist(),
                "dist_std": self.dist_std_right.tolist(),
            },
            "rvec_std_rad": self.rvec_std_rad.tolist(),
            "T_std_m": self.T_std_m.tolist(),
            "rms_px": float(self.rms_px),
            "per_view_rms_px": self.per_view_rms_px.tolist(),
        }
        if self.method:
            out["method"] = self.method
        return out


def _std(data: dict[str, Any], key: str, size: int | None, source: str, prefix: str) -> np.ndarray:
    name = prefix + key
    arr = number_field(data, key, source, name)
    if (size is None and arr.ndim != 0) or (size is not None and arr.shape != (size,)):
        want = "one number" if size is None else f"a list of {size} numbers"
        raise CalibrationError(source, name, f"must be {want}, got {data[key]!r}")
    if not np.all(np.isfinite(arr)) or np.any(arr < 0):
        raise CalibrationError(source, name, f"must be finite and not negative, got {data[key]!r}")
    return arr
