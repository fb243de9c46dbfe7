"""Identifying a dot by the AprilTag beside it (``apriltag`` design).

OpenCV's ArUco detector (``DICT_APRILTAG_36h11``, sub-pixel corners) runs on a crop around the
dot that holds the whole label, upsampled (bicubic, up to 4×) when the tag's cells would be
narrower than ``UPSAMPLE_CELL_PX``. A tag's four corners give the homography of the marker's plane
(the tag's corners are known in dot diameters), which predicts the dot's centre and size; the
tag identifies the dot when the prediction lands on the dot's ellipse.
"""

from __future__ import annotations

from functools import lru_cache

import cv2
import numpy as np

from measure.markers.codes import apriltag_dictionary
from measure.markers.design import MarkerDesign
from measure.markers.ellipse import EllipseFit

#: cells narrower than this (px, along the dot's minor axis) are upsampled to it
UPSAMPLE_CELL_PX = 8.0


@lru_cache(maxsize=1)
def _detector() -> cv2.aruco.ArucoDetector:
    params = cv2.aruco.DetectorParameters()
    params.cornerRefinementMethod = cv2.aruco.CORNER_REFINE_SUBPIX
    return cv2.aruco.ArucoDetector(apriltag_dictionary(), params)


def tag_corners_plane(design: MarkerDesign) -> np.ndarray:
    """The tag's corners (4, 2) in marker coordinates (dot diameters), in OpenCV's order:
    top-left, top-right, bottom-right, bottom-left of the tag as drawn."""
    h = 4.0 * design.tag_cell
    x = design.tag_offset
    return np.array([[x - h, h], [x + h, h], [x + h, -h], [x - h, -h]])


def read_tag(gray8: np.ndarray, dot: EllipseFit, design: MarkerDesign) -> tuple[int | None, float]:
    """The code of the tag that belongs to the dot (or None), and the distance (in dot radii)
    between the dot's centre and the tag's prediction of it."""
    reach = (design.tag_offset + 1.5 * design.field_half) / 0.5 * dot.a
    h, w = gray8.shape
    x0 = max(int(dot.center[0] - reach), 0)
    y0 = max(int(dot.center[1] - reach), 0)
    x1 = min(int(dot.center[0] + reach) + 1, w)
    y1 = min(int(dot.center[1] + reach) + 1, h)
    crop = gray8[y0:y1, x0:x1]
    # the detector needs a few pixels per cell: small or oblique tags are upsampled
    cell_px = design.tag_cell / 0.5 * dot.b
    up = int(min(max(np.ceil(UPSAMPLE_CELL_PX / cell_px), 1), 4))
    if up > 1:
        crop = cv2.resize(crop, None, fx=up, fy=up, interpolation=cv2.INTER_CUBIC)
    corners, ids, _ = _detector().detectMarkers(crop)
    if ids is None:
        return None, float("inf")
    plane = tag_corners_plane(design)
    best: tuple[int | None, float] = (None, float("inf"))
    for c, i in zip(corners, ids.ravel(), strict=True):
        # an upsampled pixel centre k is the original's (k + 0.5) / up - 0.5
        img_pts = (c.reshape(4, 2).astype(np.float64) + 0.5) / up - 0.5 + np.array([x0, y0])
        H = cv2.getPerspectiveTransform(plane.astype(np.float32), img_pts.astype(np.float32))
        p = H @ np.array([0.0, 0.0, 1.0])
        pred = p[:2] / p[2]
        # the dot's rim predicted by the tag: its mean radius must match the ellipse's
        rim = np.stack(
            [0.5 * np.cos(np.arange(8) * np.pi / 4), 0.5 * np.sin(np.arange(8) * np.pi / 4)], 1
        )
        q = cv2.perspectiveTransform(rim.reshape(-1, 1, 2), H).reshape(-1, 2)
        r_pred = float(np.mean(np.linalg.norm(q - pred, axis=1)))
        r_dot = float(np.sqrt(dot.a * dot.b))
        off = float(np.linalg.norm(pred - dot.center)) / r_dot
        if abs(r_pred / r_dot - 1.0) > 0.25:
            continue
        if off < best[1]:
            best = (int(i), off)
    if best[1] > 0.3:
        return None, best[1]
    return best
