"""Which reference markers a stereo view sees: in front of both cameras, inside both images with
a margin, and faced at no more than :data:`MAX_VIEW_ANGLE_RAD` from the marker's normal."""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from cell.referencing.observations import T_left_right, project
from measure import StereoCalibration
from robots.transforms import invert

Array = NDArray[np.float64]

#: a marker is seen only this close to face-on (rad): beyond, its ellipse is too thin to centre
MAX_VIEW_ANGLE_RAD = math.radians(60.0)
#: a marker's centre must stay this share of the image width inside the image's border
IMAGE_MARGIN_FRAC = 0.03
#: "well spread": the markers' image positions scatter at least this share of the image width
#: along their narrowest direction (not all on one line, not clumped)
SPREAD_MIN_FRAC = 0.05


def seen_each(
    stereo: StereoCalibration, T_cell_left: Array, positions_cell: Array, normals_cell: Array
) -> tuple[NDArray[np.bool_], NDArray[np.bool_]]:
    """Masks (n,) of the markers (positions and unit normals (n, 3), cell frame) that the left
    and the right camera of the head at ``T_cell_left`` see."""
    positions_cell = np.asarray(positions_cell, float).reshape(-1, 3)
    normals_cell = np.asarray(normals_cell, float).reshape(-1, 3)
    w, h = stereo.image_size
    margin = IMAGE_MARGIN_FRAC * w
    masks = []
    for side, T_cell_cam in (("left", T_cell_left), ("right", T_cell_left @ T_left_right(stereo))):
        ok = np.ones(len(positions_cell), bool)
        if len(ok) == 0:
            masks.append(ok)
            continue
        T_cam_cell = invert(T_cell_cam)
        p_cam = positions_cell @ T_cam_cell[:3, :3].T + T_cam_cell[:3, 3]
        ok &= p_cam[:, 2] > 0.05
        to_cam = T_cell_cam[:3, 3] - positions_cell
        to_cam /= np.linalg.norm(to_cam, axis=1, keepdims=True)
        ok &= np.einsum("ij,ij->i", to_cam, normals_cell) >= math.cos(MAX_VIEW_ANGLE_RAD)
        uv = project(stereo, side, T_cam_cell, positions_cell)
        ok &= (uv[:, 0] > margin) & (uv[:, 0] < w - 1 - margin)
        ok &= (uv[:, 1] > margin) & (uv[:, 1] < h - 1 - margin)
        # the lens polynomial folds points far outside the field back into the image: the
        # pinhole image of a seen point lies inside the image too (10 % slack for distortion)
        K = stereo.K_left if side == "left" else stereo.K_right
        z = np.maximum(p_cam[:, 2], 1e-9)
        pin = (p_cam[:, :2] / z[:, None]) @ np.asarray(K)[:2, :2].T + np.asarray(K)[:2, 2]
        ok &= (pin[:, 0] > -0.1 * w) & (pin[:, 0] < 1.1 * w)
        ok &= (pin[:, 1] > -0.1 * h) & (pin[:, 1] < 1.1 * h)
        masks.append(ok)
    return masks[0], masks[1]


def seen(
    stereo: StereoCalibration, T_cell_left: Array, positions_cell: Array, normals_cell: Array
) -> NDArray[np.bool_]:
    """Mask (n,) of the markers that both cameras of the head at ``T_cell_left`` see."""
    left, right = seen_each(stereo, T_cell_left, positions_cell, normals_cell)
    return left & right


def well_spread(stereo: StereoCalibration, uv_left: Array) -> bool:
    """Whether at least 4 marker centres (n, 2) px spread over the left image (module doc)."""
    uv_left = np.asarray(uv_left, float).reshape(-1, 2)
    if len(uv_left) < 4:
        return False
    sd = np.sqrt(np.linalg.eigvalsh(np.cov(uv_left.T)))
    return bool(sd[0] >= SPREAD_MIN_FRAC * stereo.image_size[0])
