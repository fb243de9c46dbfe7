"""What the head saw of the reference markers: per view, each marker's centre in the left and
the right image (pixels as the cameras deliver them, distorted), and the same as ideal pixels
(undistorted with the head's stereo calibration, same camera matrix) for the adjustments."""

from __future__ import annotations

from dataclasses import dataclass, field

import cv2
import numpy as np
from numpy.typing import NDArray

from measure import StereoCalibration

Array = NDArray[np.float64]


@dataclass(frozen=True)
class MarkerView:
    """One stereo view of markers: ``uv_left`` / ``uv_right`` map a marker id to its detected
    centre (2,) in pixels (distorted image); a marker seen in one image only is kept out of
    the other mapping. ``T_cell_left_prior``: the arm's idea of the left camera's pose (4, 4),
    the prior of a resection and the survey's starting value."""

    view_id: str
    uv_left: dict[str, Array]
    uv_right: dict[str, Array]
    T_cell_left_prior: Array = field(default_factory=lambda: np.eye(4))

    def both(self) -> list[str]:
        """The ids seen in both images, sorted."""
        return sorted(set(self.uv_left) & set(self.uv_right))

    def either(self) -> list[str]:
        """The ids seen in at least one image, sorted."""
        return sorted(set(self.uv_left) | set(self.uv_right))


def ideal_pixels(stereo: StereoCalibration, side: str, uv: Array) -> Array:
    """Undistorted pixels (n, 2) of distorted pixels ``uv`` (n, 2) of camera ``side``: the
    pinhole image the camera matrix ``K`` alone would give."""
    uv = np.asarray(uv, dtype=float).reshape(-1, 1, 2)
    if len(uv) == 0:
        return np.zeros((0, 2))
    K, dist = (
        (stereo.K_left, stereo.dist_left) if side == "left" else (stereo.K_right, stereo.dist_right)
    )
    return cv2.undistortPoints(uv, K, dist, P=K).reshape(-1, 2)


def T_left_right(stereo: StereoCalibration) -> Array:
    """The right camera's pose in the left camera's frame (4, 4): the inverse of the stereo
    calibration's ``X_right = R @ X_left + T``."""
    T = np.eye(4)
    T[:3, :3] = np.asarray(stereo.R).T
    T[:3, 3] = -np.asarray(stereo.R).T @ np.asarray(stereo.T).ravel()
    return T


def project(stereo: StereoCalibration, side: str, T_cam_cell: Array, points_cell: Array) -> Array:
    """Distorted pixels (n, 2) of cell-frame points (n, 3) in camera ``side`` whose pose is
    given by ``T_cam_cell`` (cell -> camera)."""
    K, dist = (
        (stereo.K_left, stereo.dist_left) if side == "left" else (stereo.K_right, stereo.dist_right)
    )
    rvec, _ = cv2.Rodrigues(T_cam_cell[:3, :3])
    pts = np.asarray(points_cell, dtype=float).reshape(-1, 1, 3)
    uv, _ = cv2.projectPoints(pts, rvec, T_cam_cell[:3, 3], K, dist)
    return uv.reshape(-1, 2)
