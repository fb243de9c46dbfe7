"""Chessboard corners in the board's own order, whatever order OpenCV's detector returned.

OpenCV's chessboard detectors may start a board of ``cols`` x ``rows`` inner corners at either
end: the same board seen in the left and the right image can come back in orders 180 deg
apart (one view of a calibration tour did, on the simulated head), which puts every corner of
that image on the wrong object point. The board frame (:mod:`measure.target`,
docs/conventions.md) fixes the order:

- handedness: x along a row, y down the rows, z into the plate, and the camera looks at the
  printed face along +z, so the image of (x, y) keeps the image axes' handedness: the cross
  product of the first row's direction and the first column's is positive in pixels (u right,
  v down); a mirrored order has its rows reversed;
- colour: the square spanned by the first two corners of the first two rows is black (the
  square at x, y in (0, pitch) of :func:`measure.synth.targets` and of a board printed with
  the origin on a black square); its neighbour along the row is white. Otherwise the order is
  turned by 180 deg.

A board of another convention (a white first square) then comes back consistently turned by
180 deg, which a calibration absorbs in the board's pose (a measured ``corners_file`` must
then be written in that order).
"""

from __future__ import annotations

import cv2
import numpy as np
from numpy.typing import NDArray

from measure.target import TargetSpec, to_gray8

Array = NDArray[np.float64]


def _cell_box(grid: Array, i: int, j: int, shape: tuple[int, ...]) -> tuple[int, int, int, int]:
    """Rows and columns (``y0, y1, x0, x1``, clipped to the image) of a patch a quarter of the
    square's size around the centre of the square between rows i, i+1 and columns j, j+1."""
    quad = grid[i : i + 2, j : j + 2].reshape(-1, 2)
    c = quad.mean(axis=0)
    half = max(1, int(0.125 * np.linalg.norm(grid[i, j] - grid[i + 1, j + 1])))
    x0, y0 = round(float(c[0])), round(float(c[1]))
    h, w = shape[:2]
    return max(0, y0 - half), min(h, y0 + half + 1), max(0, x0 - half), min(w, x0 + half + 1)


def _cell_means(gray8: NDArray, grid: Array, cells: list[tuple[int, int]]) -> list[float]:
    """Mean grey of each cell's patch (:func:`_cell_box`) in the image blurred by a 3 x 3
    Gaussian; only a crop around the patches is blurred, one pixel wider than they are on each
    side (what the kernel reads), so the means are those of the whole image blurred."""
    h, w = gray8.shape[:2]
    boxes = [_cell_box(grid, i, j, gray8.shape) for i, j in cells]
    y0 = max(0, min(b[0] for b in boxes) - 1)
    y1 = min(h, max(b[1] for b in boxes) + 1)
    x0 = max(0, min(b[2] for b in boxes) - 1)
    x1 = min(w, max(b[3] for b in boxes) + 1)
    if y1 <= y0 or x1 <= x0:
        return [float("nan")] * len(cells)
    # the crop's outermost pixels are in no patch unless they are the image's own border,
    # which the crop reflects as the whole image does
    crop = cv2.GaussianBlur(gray8[y0:y1, x0:x1], (3, 3), 0).astype(float)
    out = []
    for b in boxes:
        patch = crop[b[0] - y0 : b[1] - y0, b[2] - x0 : b[3] - x0]
        out.append(float(patch.mean()) if patch.size else float("nan"))
    return out


def orient_chessboard(gray: NDArray, points_px: Array, spec: TargetSpec) -> Array:
    """``points_px`` (N, 2) reordered to the board's order (module docstring)."""
    if spec.kind != "chessboard":
        return points_px
    grid = np.asarray(points_px, float).reshape(spec.rows, spec.cols, 2)
    along, down = grid[0, 1] - grid[0, 0], grid[1, 0] - grid[0, 0]
    if along[0] * down[1] - along[1] * down[0] < 0:
        grid = grid[::-1]
    first, beside = _cell_means(to_gray8(gray), grid, [(0, 0), (0, 1)])
    if first > beside:
        grid = grid[::-1, ::-1]
    return grid.reshape(-1, 2).copy()


#: the sub-pixel refinement's half window as a share of the square's side in the image, and
#: its bounds (px)
REFINE_WINDOW_SHARE = 0.06
REFINE_WINDOW_PX = (5, 15)


def refine_corners(gray: NDArray, points_px: Array, spec: TargetSpec) -> Array:
    """Chessboard corners refined again by ``cv2.cornerSubPix`` with a window sized to the
    squares (:data:`REFINE_WINDOW_SHARE` of the median square side): the detector's fixed
    5 px half window uses a few rows of pixels around each corner, a larger one averages the
    image noise over more. On the simulated head (squares of 150-170 px) the corner error
    halves, 0.16 to 0.08 px RMS, with 8-11 px half windows (15: 0.085 px)."""
    if spec.kind != "chessboard":
        return points_px
    grid = np.asarray(points_px, float).reshape(spec.rows, spec.cols, 2)
    sides = np.concatenate(
        [
            np.linalg.norm(np.diff(grid, axis=1), axis=-1).ravel(),
            np.linalg.norm(np.diff(grid, axis=0), axis=-1).ravel(),
        ]
    )
    lo, hi = REFINE_WINDOW_PX
    half = int(np.clip(round(REFINE_WINDOW_SHARE * float(np.median(sides))), lo, hi))
    crit = (cv2.TERM_CRITERIA_EPS | cv2.TERM_CRITERIA_COUNT, 100, 1e-5)
    pts = np.asarray(points_px, np.float32).reshape(-1, 1, 2).copy()
    out = cv2.cornerSubPix(to_gray8(gray), pts, (half, half), (-1, -1), crit)
    return out.reshape(-1, 2).astype(np.float64)


#: a corner farther than this from the plane the others fit (px) is detected wrongly
PLANE_TOLERANCE_PX = 2.0


def plane_outliers(
    points_px: Array, spec: TargetSpec, K: Array, dist: Array
) -> tuple[Array, Array]:
    """Each corner's distance (px) from the board plane the others fit, and the plane's
    prediction of every corner (px): the corners undistorted with the camera's lens, a
    homography from the board fitted robustly (RANSAC, 1 px), mapped back through the lens.
    An intrinsic error of a pixel or two moves every corner alike and does not show."""
    obj = spec.object_points()[:, :2].astype(np.float64)
    pts = np.asarray(points_px, np.float64).reshape(-1, 1, 2)
    norm = cv2.undistortPoints(pts, K, dist).reshape(-1, 2)
    f = float(K[0, 0])
    H, _mask = cv2.findHomography(obj, norm * f, cv2.RANSAC, 1.0)
    if H is None:
        return np.full(len(obj), np.inf), np.asarray(points_px, float)
    pred = cv2.perspectiveTransform(obj.reshape(-1, 1, 2), H).reshape(-1, 2) / f
    rays = np.column_stack([pred, np.ones(len(pred))])
    px = cv2.projectPoints(rays, np.zeros(3), np.zeros(3), K, dist)[0].reshape(-1, 2)
    return np.linalg.norm(px - np.asarray(points_px, float), axis=1), px


def repair_outliers(
    gray: NDArray, points_px: Array, spec: TargetSpec, K: Array, dist: Array
) -> tuple[Array, str]:
    """Corners off the board's plane (:func:`plane_outliers`) refined again from the plane's
    prediction (the detector's 5 px half window); ``(corners, "")`` or, when one stays off,
    the reason ("corner 1 is 27.0 px off the plate's plane")."""
    off, pred = plane_outliers(points_px, spec, K, dist)
    bad = np.flatnonzero(off > PLANE_TOLERANCE_PX)
    if len(bad) == 0:
        return points_px, ""
    out = np.asarray(points_px, float).copy()
    crit = (cv2.TERM_CRITERIA_EPS | cv2.TERM_CRITERIA_COUNT, 100, 1e-5)
    start = pred[bad].astype(np.float32).reshape(-1, 1, 2).copy()
    out[bad] = cv2.cornerSubPix(to_gray8(gray), start, (5, 5), (-1, -1), crit).reshape(-1, 2)
    off, _ = plane_outliers(out, spec, K, dist)
    worst = int(np.argmax(off))
    if off[worst] > PLANE_TOLERANCE_PX:
        return out, f"corner {worst + 1} is {off[worst]:.1f} px off the plate's plane"
    return out, ""
