"""The target's corners in the images of a poses CSV: the observations of an offline calibration.

Every image named by a row is read (8 or 16 bit, colour turned to gray) and the target is
searched with :func:`measure.target.find_target`, its corners put in the board frame's
order (:func:`cell.calibration.capture.orient_chessboard`: docs/conventions.md). An image that
cannot be read, has another size than the calibration's, or does not show the whole target is
refused with its file and row named: a view without the target cannot be used, and guessing
which image is wrong is left to the user. When the first image lacks only the target, up to
:data:`HINT_ROWS` other rows' images are searched too: if none shows it, the board size given
(``--cols``/``--rows``) is the likely mistake and the refusal says so.
"""

from __future__ import annotations

import logging
from pathlib import Path

import cv2
import numpy as np

from cell.calibration.capture.orient import orient_chessboard
from cell.calibration.errors import CalibrationDataError, TargetNotFoundError
from cell.calibration.estimate.observations import CalibrationObservations, CalibrationView, Cameras
from cell.calibration.estimate.soft_views import DroppedView, is_soft
from cell.calibration.inputs.posecsv import PoseRow
from measure.target import MAX_EDGE_WIDTH_PX, TargetSpec, find_target

log = logging.getLogger(__name__)
#: when the first image lacks the target, how many other rows' images (left or only, spread
#: over the set) are searched before the board size is blamed: each costs the detector's
#: exhaustive search, 0.7 s at 320 x 256 px
HINT_ROWS = 6


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
        raise TargetNotFoundError(src, f"image {path.name}: {det.reason}", row)
    return orient_chessboard(img, det.points, spec)  # the board frame's order


def board_size_hint(spec: TargetSpec) -> str:
    """The refusal's hint when no image shows the target: the board size may be wrong."""
    counted = "inner corners (squares minus one)" if spec.kind == "chessboard" else "circles"
    return (
        f"is the board size right? --cols {spec.cols} --rows {spec.rows} count the "
        f"{spec.kind}'s {counted} along each side"
    )


def observations_from_images(
    rows: tuple[PoseRow, ...],
    images_dir: str | Path,
    spec: TargetSpec,
    cameras: Cameras,
    source: str,
    max_edge_width_px: float = MAX_EDGE_WIDTH_PX,
    strict: bool = False,
    dropped: list[DroppedView] | None = None,
) -> CalibrationObservations:
    """Detect the target in every row's image(s) and build the observations; an image whose
    edges are wider than ``max_edge_width_px`` (10-90 % rise) counts as too blurred: its view
    is appended to ``dropped`` and left out (:mod:`cell.calibration.estimate.soft_views`), or,
    with ``strict``, refused."""
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
    blur = max_edge_width_px

    def view(r: PoseRow) -> CalibrationView:
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
        return CalibrationView(name, left, right, r.q_rad, r.T_base_tool0)

    views = []
    for k, r in enumerate(rows):
        try:
            views.append(view(r))
        except TargetNotFoundError as exc:
            if not strict and is_soft(exc.reason.split(": ", 1)[-1]):
                if dropped is not None:
                    dropped.append(DroppedView(r.row, exc.reason))
                continue
            if views:
                raise
            others = _spread(rows[k + 1 :], HINT_ROWS)
            if _seen_in_any(others, folder, spec, cameras, source, blur):
                raise
            where = (
                "any other row's image"
                if len(others) == len(rows) - k - 1
                else (f"the {len(others)} other rows' images searched")
            )
            raise CalibrationDataError(
                source,
                f"row {r.row}: {exc.reason}, nor in {where}; {board_size_hint(spec)}",
            ) from None
    return CalibrationObservations(tuple(views), spec, cameras, source)


def _spread(rows: tuple[PoseRow, ...], n: int) -> tuple[PoseRow, ...]:
    """At most ``n`` of ``rows``, spread evenly over them (all when there are no more)."""
    if len(rows) <= n:
        return rows
    return tuple(rows[int(i)] for i in np.linspace(0, len(rows) - 1, n).round())


def _seen_in_any(rows, folder: Path, spec: TargetSpec, cameras: Cameras, src: str, blur: float):
    """Whether the target is found in the (left or only) image of any of these rows."""
    for r in rows:
        try:
            _corners(
                folder / (r.left_image or r.image), spec, cameras.left.image_size, src, r.row, blur
            )
        except TargetNotFoundError:
            continue
        return True
    return False
