"""What a stereo pair shows of the markers: each marker found and identified in both images
(:func:`measure.markers.detect_markers`), its ellipse centre corrected for the perspective bias
of a circle's projected centre, as a :class:`MarkerView`.

The bias (the centre of a circle's image is not the image of its centre; up to a few tenths of
a pixel for a 5 mm dot tilted 30° at 0.25 m) depends on the marker's pose in the camera, which
the prior gives well enough: a 1 mm error of the prior changes the bias by under 0.001 px.
"""

from __future__ import annotations

from collections.abc import Mapping

import cv2
import numpy as np
from numpy.typing import NDArray

from cell.referencing.observations import MarkerView, T_left_right, ideal_pixels
from measure import StereoCalibration
from measure.markers import (
    DEFAULT_DESIGN,
    MarkerDetection,
    circle_center_bias_many_px,
    detect_markers,
)
from robots.transforms import invert

Array = NDArray[np.float64]

#: a marker known by its id: centre (3,) and unit normal (3,) in the cell frame, dot radius (m)
MarkerGeometry = Mapping[str, tuple[Array, Array, float]]


def _camera(stereo: StereoCalibration, side: str) -> tuple[Array, Array]:
    if side == "left":
        return np.asarray(stereo.K_left, float), np.asarray(stereo.dist_left, float)
    return np.asarray(stereo.K_right, float), np.asarray(stereo.dist_right, float)


def distorted_pixels(stereo: StereoCalibration, side: str, uv_ideal: Array) -> Array:
    """Image pixels (n, 2) of ideal (undistorted, same ``K``) pixels (n, 2) of camera ``side``;
    the inverse of :func:`cell.referencing.observations.ideal_pixels`."""
    K, dist = _camera(stereo, side)
    uv = np.asarray(uv_ideal, float).reshape(-1, 2)
    if len(uv) == 0:
        return np.zeros((0, 2))
    xy = (uv - K[:2, 2]) @ np.linalg.inv(K[:2, :2]).T
    pts = np.hstack([xy, np.ones((len(xy), 1))]).reshape(-1, 1, 3)
    out, _ = cv2.projectPoints(pts, np.zeros(3), np.zeros(3), K, dist)
    return out.reshape(-1, 2)


#: a marker's printed label reaches this far beyond its dot's image, as a share of the label
#: radius (the ellipse's axes are the dot's; the label's edge blurs outwards)
LABEL_MARGIN = 1.15

Detections = tuple[list[MarkerDetection], list[MarkerDetection]]


def detect_pair(
    left: np.ndarray, right: np.ndarray, stereo: StereoCalibration, codes: Mapping[int, str]
) -> Detections:
    """The markers of ``codes`` found and identified in the left and the right image."""
    return tuple(
        detect_markers(image, *_camera(stereo, side), codes=set(codes))
        for side, image in (("left", left), ("right", right))
    )  # type: ignore[return-value]


def label_circles(detections: Detections) -> tuple[list, list]:
    """Per image, a circle ``(x_px, y_px, radius_px)`` around each detected marker's label (a
    dark disc a hole finder would otherwise take for a hole)."""
    k = DEFAULT_DESIGN.outer_radius(1.0) * LABEL_MARGIN  # label radius in dot diameters
    return tuple(
        [(float(d.center_px[0]), float(d.center_px[1]), k * float(max(d.ellipse[1]))) for d in dets]
        for dets in detections
    )  # type: ignore[return-value]


def observe_pair(
    left: np.ndarray,
    right: np.ndarray,
    stereo: StereoCalibration,
    codes: Mapping[int, str],
    geometry: MarkerGeometry,
    view_id: str,
    T_cell_left_prior: Array,
) -> MarkerView:
    """The markers of ``codes`` (code -> id) found in both images of one view; each centre with
    its perspective bias removed (computed at the prior pose from ``geometry``), as image
    pixels."""
    dets = detect_pair(left, right, stereo, codes)
    return observe_detections(dets, stereo, codes, geometry, view_id, T_cell_left_prior)


def observe_detections(
    detections: Detections,
    stereo: StereoCalibration,
    codes: Mapping[int, str],
    geometry: MarkerGeometry,
    view_id: str,
    T_cell_left_prior: Array,
) -> MarkerView:
    """:func:`observe_pair` from detections already made."""
    T_prior = np.asarray(T_cell_left_prior, float)
    cams = {"left": T_prior, "right": T_prior @ T_left_right(stereo)}
    found: list[dict[str, Array]] = []
    for side, dets in zip(("left", "right"), detections, strict=True):
        K, _ = _camera(stereo, side)
        T_cam_cell = invert(cams[side])
        ids = [codes[det.code] for det in dets]
        uv = ideal_pixels(stereo, side, np.array([det.center_px for det in dets], float))
        known = [k for k, mid in enumerate(ids) if mid in geometry]
        if known:
            p = np.array([geometry[ids[k]][0] for k in known], float)
            n = np.array([geometry[ids[k]][1] for k in known], float)
            r = np.array([geometry[ids[k]][2] for k in known], float)
            c_cam = p @ T_cam_cell[:3, :3].T + T_cam_cell[:3, 3]
            front = c_cam[:, 2] > 0
            rows = np.asarray(known)[front]
            uv[rows] -= circle_center_bias_many_px(
                K, c_cam[front], n[front] @ T_cam_cell[:3, :3].T, r[front]
            )
        found.append(dict(zip(ids, distorted_pixels(stereo, side, uv), strict=True)))
    return MarkerView(view_id, found[0], found[1], T_prior)
