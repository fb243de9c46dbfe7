"""The standard stereo head of the benchmarks and scene placement helpers."""

from __future__ import annotations

import math

import numpy as np

from measure.calibration import StereoCalibration
from measure.head import head_frame

#: the standard head: two 2448 × 2048 cameras, 3.45 µm pixels, 16 mm lenses,
#: 100 mm baseline, toed in to meet at 250 mm
STANDARD_IMAGE_SIZE = (2448, 2048)
STANDARD_PIXEL_M = 3.45e-6
STANDARD_FOCAL_M = 16e-3
STANDARD_BASELINE_M = 0.100
STANDARD_STANDOFF_M = 0.250


def _camera_in_head(x_m: float, standoff_m: float) -> np.ndarray:
    """Pose ``T_head_cam`` of a camera at head x = ``x_m`` looking at (0, 0, standoff)."""
    z = np.array([-x_m, 0.0, standoff_m])
    z /= np.linalg.norm(z)
    y = np.array([0.0, 1.0, 0.0])
    x = np.cross(y, z)
    T = np.eye(4)
    T[:3, 0], T[:3, 1], T[:3, 2], T[:3, 3] = x, y, z, (x_m, 0.0, 0.0)
    return T


def toed_in_stereo(
    image_size: tuple[int, int] = STANDARD_IMAGE_SIZE,
    pixel_m: float = STANDARD_PIXEL_M,
    focal_m: float = STANDARD_FOCAL_M,
    baseline_m: float = STANDARD_BASELINE_M,
    standoff_m: float = STANDARD_STANDOFF_M,
    dist_left: tuple[float, ...] = (-0.05, 0.02, 1.0e-4, -5.0e-5, 0.0),
    dist_right: tuple[float, ...] = (-0.045, 0.015, -8.0e-5, 6.0e-5, 0.0),
) -> StereoCalibration:
    """A symmetric toed-in stereo head; cameras meet at ``standoff_m`` on the head z axis."""
    w, h = image_size
    f_px = focal_m / pixel_m
    K = np.array([[f_px, 0.0, (w - 1) / 2.0], [0.0, f_px, (h - 1) / 2.0], [0.0, 0.0, 1.0]])
    T_head_left = _camera_in_head(-baseline_m / 2.0, standoff_m)
    T_head_right = _camera_in_head(baseline_m / 2.0, standoff_m)
    T_right_left = np.linalg.inv(T_head_right) @ T_head_left
    return StereoCalibration(
        image_size=(w, h),
        K_left=K.copy(),
        dist_left=np.array(dist_left, dtype=float),
        K_right=K.copy(),
        dist_right=np.array(dist_right, dtype=float),
        R=T_right_left[:3, :3].copy(),
        T=T_right_left[:3, 3].copy(),
        source="<standard head>",
    )


def standard_stereo() -> StereoCalibration:
    """The benchmarks' standard head (see module constants), with small lens distortion."""
    return toed_in_stereo()


def hole_in_view(
    stereo: StereoCalibration,
    tilt_rad: float,
    azimuth_rad: float = 0.0,
    offset_head_m: tuple[float, float, float] = (0.0, 0.0, 0.0),
    standoff_m: float = STANDARD_STANDOFF_M,
) -> tuple[np.ndarray, np.ndarray]:
    """Place a hole in front of the head; return ``(center_m, normal)`` in the LEFT camera frame.

    The hole centre sits at ``standoff_m`` along the head z axis plus ``offset_head_m``
    (head frame, metres); its normal points toward the head (−z of the head) tilted by
    ``tilt_rad`` about the in-plane axis at ``azimuth_rad`` from head x.
    """
    T = head_frame(stereo)
    c_head = np.array([0.0, 0.0, standoff_m]) + np.asarray(offset_head_m, dtype=float)
    axis = np.array([math.cos(azimuth_rad), math.sin(azimuth_rad), 0.0])
    n0 = np.array([0.0, 0.0, -1.0])
    # Rodrigues rotation of n0 about axis by tilt
    n_head = (
        n0 * math.cos(tilt_rad)
        + np.cross(axis, n0) * math.sin(tilt_rad)
        + axis * (axis @ n0) * (1.0 - math.cos(tilt_rad))
    )
    center = T[:3, :3] @ c_head + T[:3, 3]
    normal = T[:3, :3] @ n_head
    return center, normal / np.linalg.norm(normal)
