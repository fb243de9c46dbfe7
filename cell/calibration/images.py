"""The target's corners in the images of a poses CSV: the observations of an offline calibration.

Every image named by a row is read (8 or 16 bit, colour turned to gray) and the target is
searched with :func:`measure.target.find_target`. An image that cannot be read, has another
size than the calibration's, or does not show the whole target is refused with its file and
row named: a view without the target cannot be used, and guessing which image is wrong is
left to the user.
"""

from __future__ import annotations

import logging
from pathlib import Path

import cv2
import numpy as np

from cell.calibration.errors import CalibrationDataError
from cell.calibration.observations import CalibrationObservations, CalibrationView, Cameras
from cell.calibration.posecsv import PoseRow
from measure.target import MAX_EDGE_WIDTH_PX, TargetSpec, find_target

log = logging.getLogger(__name__)


def _read_gray(path: Path, src: str, row: int) -> np.ndarray:
    if not path.is_file():
        raise CalibrationDataError(src, f"image {path}: no such file", row)
    img = cv2.imread(str(path), cv2.IMREAD_UNCHANGED)
    if img is None:
        raise CalibrationDataError(src, f"image {path}: not a readable image", row)
    if img.ndim == 3:
        img = cv2.cvtColor(img[:, :, :3], cv2.COLOR_BGR2GRAY)
    return img


def _corners(
    path: Path, spec: TargetSpec, size: tuple[int, int], src: str, row: int, blur_px: float
) -> np.ndarray:
    img = _read_gray(path, src, row)
    h, w = img.shape[:2]
    if (w, h) != tuple(size):
        raise CalibrationDataError(
            src, f"image {path.name} is {w}x{h} px, the calibration is for {size[0]}x{size[1]}", row
        )
    det = find_target(img, spec, blur_px)
    if det.points is None:
        raise CalibrationDataError(src, f"image {path.name}: {det.reason}", row)
    return det.points


def observations_from_images(
    rows: tuple[PoseRow, ...],
    images_dir: str | Path,
    spec: TargetSpec,
    cameras: Cameras,
    source: str,
    max_edge_width_px: float = MAX_EDGE_WIDTH_PX,
) -> CalibrationObservations:
    """Detect the target in every row's image(s) and build the observations; an image whose
    edges are wider than ``max_edge_width_px`` (10-90 % rise) counts as too blurred."""
    folder = Path(images_dir)
    if not folder.is_dir():
        raise CalibrationDataError(str(images_dir), "not a folder of images")
    stereo_rows = rows[0].left_image is not None
    if stereo_rows and not cameras.stereo:
        raise CalibrationDataError(source, "stereo pairs (left_image, right_image) need --stereo")
    if not stereo_rows and cameras.stereo:
        raise CalibrationDataError(
            source, "mono images (image) with --stereo: give left_image, right_image"
        )
    views = []
    blur = max_edge_width_px
    for r in rows:
        if stereo_rows:
            left = _corners(
                folder / r.left_image, spec, cameras.left.image_size, source, r.row, blur
            )
            right = _corners(
                folder / r.right_image, spec, cameras.right.image_size, source, r.row, blur
            )
            name = f"{r.left_image} / {r.right_image}"
        else:
            left = _corners(folder / r.image, spec, cameras.left.image_size, source, r.row, blur)
            right = None
            name = r.image
        log.info("row %d: target found in %s", r.row, name)
        views.append(CalibrationView(name, left, right, r.q_rad, r.T_base_tool0))
    return CalibrationObservations(tuple(views), spec, cameras, source)
