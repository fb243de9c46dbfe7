"""Stereo calibration: the ``stereo.json`` file, validation and rectification.

``stereo.json`` (see ``DESIGN.md``)::

    {"image_size": [w, h],
     "left":  {"K": [[fx, 0, cx], [0, fy, cy], [0, 0, 1]], "dist": [k1, k2, p1, p2, k3]},
     "right": {"K": ..., "dist": ...},
     "R": [[...], [...], [...]], "T": [tx, ty, tz],
     "uncertainty": {...}}      # optional: see measure.calibration_uncertainty

``R`` and ``T`` (metres) map left-camera coordinates into the right camera,
``X_right = R @ X_left + T``, exactly as ``cv2.stereoCalibrate`` returns them. Both
cameras use the optical convention (x right, y down, z forward) and OpenCV's pixel
convention (pixel centres at integer coordinates).
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path
from typing import Any

import cv2
import numpy as np

from measure.calibration_fields import number_field
from measure.calibration_uncertainty import CalibrationUncertainty
from measure.errors import CalibrationError

#: undistortion iterations: converged far below a micro-pixel for any realistic lens
_UNDISTORT_CRITERIA = (cv2.TERM_CRITERIA_COUNT | cv2.TERM_CRITERIA_EPS, 30, 1e-12)


@dataclass(frozen=True)
class Rectification:
    """Rectifying rotations and projections (``cv2.stereoRectify``, zero disparity at infinity).

    ``R1``/``R2`` rotate left/right camera coordinates into the rectified frames,
    ``P1``/``P2`` (3×4) project rectified-left coordinates (metres) to rectified pixels.
    """

    R1: np.ndarray
    R2: np.ndarray
    P1: np.ndarray
    P2: np.ndarray


@dataclass(frozen=True, eq=False)
class StereoCalibration:
    """Intrinsics of both cameras and the left→right extrinsics.

    Attributes:
        image_size: ``(width, height)`` in pixels, the same for both cameras.
        K_left, K_right: 3×3 camera matrices (pixels).
        dist_left, dist_right: distortion ``(k1, k2, p1, p2, k3)`` (OpenCV order).
        R, T: ``X_right = R @ X_left + T`` with ``T`` in metres.
        source: where the calibration came from (file path), for error messages.
        uncertainty: one-sigma uncertainties of the parameters, when the calibration that
            wrote the file estimated them (``None`` otherwise).
    """

    image_size: tuple[int, int]
    K_left: np.ndarray
    dist_left: np.ndarray
    K_right: np.ndarray
    dist_right: np.ndarray
    R: np.ndarray
    T: np.ndarray
    source: str = field(default="<memory>", compare=False)
    uncertainty: CalibrationUncertainty | None = field(default=None, compare=False)

    def __post_init__(self) -> None:
        _validate(self)

    # ------------------------------------------------------------------ file I/O
    @classmethod
    def load(cls, path: str | Path) -> StereoCalibration:
        """Read a ``stereo.json`` file; raise :class:`CalibrationError` naming the bad field."""
        src = str(path)
        try:
            data = json.loads(Path(path).read_text())
        except FileNotFoundError:
            raise CalibrationError(src, "file", "no such file") from None
        except (OSError, UnicodeDecodeError) as exc:
            raise CalibrationError(src, "file", f"cannot read: {exc}") from None
        except json.JSONDecodeError as exc:
            raise CalibrationError(src, "file", f"not valid JSON: {exc}") from None
        return cls.from_dict(data, source=src)

    @classmethod
    def from_dict(cls, data: Any, source: str = "<memory>") -> StereoCalibration:
        """Build from the parsed ``stereo.json`` dictionary (see module docstring)."""
        if not isinstance(data, dict):
            raise CalibrationError(source, "<root>", "must be a JSON object")
        size = _array(data, "image_size", (2,), source)
        if np.any(size <= 0) or np.any(size != np.round(size)):
            raise CalibrationError(
                source, "image_size", f"must be two positive integers, got {data['image_size']!r}"
            )
        cams = {}
        for side in ("left", "right"):
            cam = data.get(side)
            if not isinstance(cam, dict):
                raise CalibrationError(source, side, "missing or not an object with K and dist")
            K = _array(cam, "K", (3, 3), source, prefix=f"{side}.")
            dist = _array(cam, "dist", None, source, prefix=f"{side}.")
            cams[side] = (K, dist)
        return cls(
            image_size=(int(size[0]), int(size[1])),
            K_left=cams["left"][0],
            dist_left=cams["left"][1],
            K_right=cams["right"][0],
            dist_right=cams["right"][1],
            R=_array(data, "R", (3, 3), source),
            T=_array(data, "T", (3,), source),
            source=source,
            uncertainty=(
                CalibrationUncertainty.from_dict(data["uncertainty"], source)
                if "uncertainty" in data
                else None
            ),
        )

    def to_dict(self) -> dict[str, Any]:
        """The ``stereo.json`` dictionary (plain lists, SI units)."""
        out: dict[str, Any] = {
            "image_size": [int(self.image_size[0]), int(self.image_size[1])],
            "left": {"K": self.K_left.tolist(), "dist": self.dist_left.tolist()},
            "right": {"K": self.K_right.tolist(), "dist": self.dist_right.tolist()},
            "R": self.R.tolist(),
            "T": self.T.tolist(),
        }
        if self.uncertainty is not None:
            out["uncertainty"] = self.uncertainty.to_dict()
        return out

    def save(self, path: str | Path) -> None:
        """Write ``stereo.json`` (atomically: a temporary file renamed over the target)."""
        path = Path(path)
        tmp = path.with_name(path.name + ".tmp")
        tmp.write_text(json.dumps(self.to_dict(), indent=2) + "\n")
        tmp.replace(path)

    # ------------------------------------------------------------------ geometry
    @property
    def baseline_m(self) -> float:
        """Distance between the two camera centres (metres)."""
        return float(np.linalg.norm(self.T))

    @property
    def right_center_in_left(self) -> np.ndarray:
        """Right camera centre in the left camera frame (metres), ``-Rᵀ T``."""
        return -self.R.T @ self.T

    @cached_property
    def rectification(self) -> Rectification:
        """Rectification of this pair (computed once)."""
        R1, R2, P1, P2, *_ = cv2.stereoRectify(
            self.K_left,
            self.dist_left,
            self.K_right,
            self.dist_right,
            tuple(self.image_size),
            self.R,
            self.T.reshape(3, 1),
            flags=cv2.CALIB_ZERO_DISPARITY,
            alpha=-1,
        )
        return Rectification(R1=R1, R2=R2, P1=P1, P2=P2)

    def check_image(self, shape: tuple[int, ...], which: str) -> None:
        """Raise :class:`CalibrationError` unless an image of ``shape`` (h, w) fits."""
        h, w = shape[:2]
        if (w, h) != tuple(self.image_size):
            raise CalibrationError(
                self.source,
                "image_size",
                f"calibrated for {self.image_size[0]}x{self.image_size[1]} px but the "
                f"{which} image is {w}x{h} px",
            )

    def undistort_rectify(self, pts_px: np.ndarray, side: str) -> np.ndarray:
        """Map distorted pixel points (N, 2) of one camera to rectified pixels (N, 2)."""
        rect = self.rectification
        if side == "left":
            K, d, Rr, P = self.K_left, self.dist_left, rect.R1, rect.P1
        else:
            K, d, Rr, P = self.K_right, self.dist_right, rect.R2, rect.P2
        pts = np.ascontiguousarray(pts_px, dtype=np.float64).reshape(-1, 1, 2)
        if len(pts) == 0:
            return np.zeros((0, 2))
        out = cv2.undistortPoints(pts, K, d, None, Rr, P, _UNDISTORT_CRITERIA)
        return out.reshape(-1, 2)

    def normalized(self, pts_px: np.ndarray, side: str) -> np.ndarray:
        """Distorted pixels (N, 2) → ideal normalised image coordinates (N, 2) (x/z, y/z)."""
        K, d = (self.K_left, self.dist_left) if side == "left" else (self.K_right, self.dist_right)
        pts = np.ascontiguousarray(pts_px, dtype=np.float64).reshape(-1, 1, 2)
        if len(pts) == 0:
            return np.zeros((0, 2))
        return cv2.undistortPoints(pts, K, d, None, None, None, _UNDISTORT_CRITERIA).reshape(-1, 2)

    def project(self, X_left: np.ndarray, side: str) -> np.ndarray:
        """Project left-camera points (N, 3, metres) into distorted pixels (N, 2) of ``side``."""
        X = np.asarray(X_left, dtype=np.float64).reshape(-1, 3)
        if side == "left":
            rvec, tvec, K, d = np.zeros(3), np.zeros(3), self.K_left, self.dist_left
        else:
            rvec, tvec, K, d = (
                cv2.Rodrigues(self.R)[0].ravel(),
                self.T,
                self.K_right,
                self.dist_right,
            )
        px, _ = cv2.projectPoints(X, rvec, tvec, K, d)
        return px.reshape(-1, 2)


def _array(
    data: dict[str, Any], key: str, shape: tuple[int, ...] | None, source: str, prefix: str = ""
) -> np.ndarray:
    name = prefix + key
    arr = number_field(data, key, source, name)
    if shape is None:
        if arr.ndim != 1 or arr.size not in (4, 5, 8, 12, 14):
            raise CalibrationError(
                source, name, f"must be a list of 4, 5, 8, 12 or 14 coefficients, got {data[key]!r}"
            )
    elif arr.shape != shape:
        raise CalibrationError(source, name, f"must have shape {list(shape)}, got {data[key]!r}")
    if not np.all(np.isfinite(arr)):
        raise CalibrationError(source, name, f"holds non-finite values: {data[key]!r}")
    return arr


def _validate(cal: StereoCalibration) -> None:
    src = cal.source
    w, h = cal.image_size
    if w <= 0 or h <= 0:
        raise CalibrationError(src, "image_size", f"must be positive, got {cal.image_size}")
    for side, K in (("left", cal.K_left), ("right", cal.K_right)):
        if K.shape != (3, 3) or K[0, 0] <= 0 or K[1, 1] <= 0 or abs(K[2, 2] - 1.0) > 1e-9:
            raise CalibrationError(src, f"{side}.K", f"not a camera matrix: {K.tolist()}")
        if not (0 <= K[0, 2] < w and 0 <= K[1, 2] < h):
            raise CalibrationError(
                src,
                f"{side}.K",
                f"principal point ({K[0, 2]}, {K[1, 2]}) lies outside the {w}x{h} image",
            )
    ortho = cal.R @ cal.R.T
    if (
        cal.R.shape != (3, 3)
        or not np.allclose(ortho, np.eye(3), atol=1e-6)
        or np.linalg.det(cal.R) < 0
    ):
        raise CalibrationError(src, "R", "not a rotation matrix")
    if abs(cal.T[0]) < abs(cal.T[1]):
        raise CalibrationError(
            src, "T", f"the cameras must sit side by side (|Tx| > |Ty|), got {cal.T.tolist()}"
        )
    if not math.isfinite(cal.baseline_m) or cal.baseline_m <= 1e-6:
        raise CalibrationError(
            src, "T", f"baseline must be positive (metres), got {cal.T.tolist()}"
        )
