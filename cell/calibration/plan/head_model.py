"""The stereo head as the calibration-view planner takes it (``planner.calibration.StereoModel``).

The TCP is the head frame (:func:`measure.head_frame`), so ``T_tcp_left = T_left_head^-1`` and
``T_tcp_right = T_tcp_left @ T_left_right`` with ``X_right = R @ X_left + T`` from the stereo
calibration. Each camera projects through OpenCV's own lens model (``cv2.projectPoints`` with the
file's ``K`` and distortion), the model the detector and the calibration use.
"""

from __future__ import annotations

import cv2
import numpy as np
from numpy.typing import NDArray

from measure import StereoCalibration, head_frame
from planner.calibration import Projector, StereoModel
from robots.transforms import invert, make_transform


def _projector(K: NDArray[np.float64], dist: NDArray[np.float64]) -> Projector:
    K = np.asarray(K, dtype=float)
    dist = np.asarray(dist, dtype=float)

    def project(P: NDArray[np.float64]) -> NDArray[np.float64]:
        pts = np.asarray(P, dtype=float).reshape(-1, 1, 3)
        uv, _ = cv2.projectPoints(pts, np.zeros(3), np.zeros(3), K, dist)
        return uv.reshape(-1, 2)

    return project


def stereo_model(stereo: StereoCalibration) -> StereoModel:
    """The planner's view of ``stereo`` (module docstring); poses in metres."""
    T_tcp_left = invert(head_frame(stereo))
    T_left_right = invert(make_transform(stereo.R, stereo.T))
    return StereoModel(
        T_tcp_left=T_tcp_left,
        T_tcp_right=T_tcp_left @ T_left_right,
        image_size=(int(stereo.image_size[0]), int(stereo.image_size[1])),
        project_left=_projector(stereo.K_left, stereo.dist_left),
        project_right=_projector(stereo.K_right, stereo.dist_right),
    )
