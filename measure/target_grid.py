"""Whether a detection's corners form the board's grid: catches a board size given wrong.

OpenCV's detectors return ``cols × rows`` points whenever they can find that many, and on a
board with fewer inner corners the sector-based detector takes the plate's outer edge as one
more row or column of "corners" (one pitch outside the last real one: the spacing stays even).
Three checks, each with the figure that failed:

- **homography residual**: a flat grid is one homography of the points' grid coordinates
  (plus the lens' distortion): RMS residual at most :data:`MAX_RESIDUAL_FRAC` of the median
  spacing;
- **spacing**: along every row and column, consecutive spacings differ by at most the
  ratio :data:`MAX_SPACING_RATIO` (perspective changes them slowly);
- **border** (chessboards): the squares of the ring just outside the corners must alternate
  dark and light as the board's inner squares do, on every side that lies in the image; past
  a plate's edge (a corner row or column too many) they are the plate's plain margin.
"""

from __future__ import annotations

import cv2
import numpy as np

#: the homography's RMS residual, as a share of the median corner spacing
MAX_RESIDUAL_FRAC = 0.25
#: the largest ratio between two consecutive spacings along a row or a column
MAX_SPACING_RATIO = 1.6
#: the share of a side's outer squares that must show the colour of their place
MIN_BORDER_SHARE = 0.7


def grid_problem(img: np.ndarray, pts: np.ndarray, grid: np.ndarray, cols: int, rows: int,
                 chessboard: bool) -> str:  # fmt: skip
    """ "" when ``pts`` ((cols × rows, 2) px, row-major as OpenCV gives them) form the board's
    grid (``grid``: each point's place on the board in pitches, (cols × rows, 2)) in the 8-bit
    ``img``, else why not (one phrase with its figure)."""
    P = np.asarray(pts, float).reshape(rows, cols, 2)
    grid = np.asarray(grid, float)
    steps = np.concatenate([np.linalg.norm(np.diff(P, axis=1), axis=2).ravel(),
                            np.linalg.norm(np.diff(P, axis=0), axis=2).ravel()])  # fmt: skip
    pitch = float(np.median(steps))
    if pitch <= 0:
        return "corners on top of one another"
    ratio = _worst_spacing_ratio(P)
    if ratio > MAX_SPACING_RATIO:
        return f"uneven corner spacing (ratio {ratio:.2f} between neighbours)"
    H, _ = cv2.findHomography(grid, P.reshape(-1, 2), 0)
    if H is None:
        return "corners that no homography maps onto a grid"
    res = cv2.perspectiveTransform(grid[None], H)[0] - P.reshape(-1, 2)
    rms = float(np.sqrt(np.mean(np.sum(res**2, axis=1))))
    if rms > MAX_RESIDUAL_FRAC * pitch:
        return f"corners off a flat grid (homography residual {rms:.1f} px, spacing {pitch:.0f} px)"
    if chessboard:
        side = _border_side(img, H, cols, rows, pitch)
        if side:
            return f"no board square beyond the {side} corners (the plate's edge?)"
    return ""


def _worst_spacing_ratio(P: np.ndarray) -> float:
    worst = 1.0
    for axis in (0, 1):
        d = np.linalg.norm(np.diff(P, axis=axis), axis=2)
        a, b = (d[:-1], d[1:]) if axis == 0 else (d[:, :-1], d[:, 1:])
        if a.size:
            r = np.maximum(a, b) / np.maximum(np.minimum(a, b), 1e-9)
            worst = max(worst, float(r.max()))
    return worst


def _sample(img: np.ndarray, H: np.ndarray, centres: np.ndarray, half_px: int) -> np.ndarray:
    """Mean intensity of a square window at each grid position (NaN: outside the image)."""
    px = cv2.perspectiveTransform(centres[None].astype(float), H)[0]
    h, w = img.shape[:2]
    out = np.full(len(px), np.nan)
    for k, (x, y) in enumerate(px):
        x0, y0 = int(np.rint(x)) - half_px, int(np.rint(y)) - half_px
        x1, y1 = x0 + 2 * half_px + 1, y0 + 2 * half_px + 1
        if x0 >= 0 and y0 >= 0 and x1 <= w and y1 <= h:
            out[k] = float(img[y0:y1, x0:x1].mean())
    return out


def _border_side(img: np.ndarray, H: np.ndarray, cols: int, rows: int, pitch: float) -> str:
    """The first side ("first row's", "last column's", ...) whose outer squares do not
    alternate as the board's do; "" when every side in the image does."""
    half = max(1, int(0.15 * pitch))
    jj, ii = np.meshgrid(np.arange(cols - 1) + 0.5, np.arange(rows - 1) + 0.5)
    inner = np.stack([jj.ravel(), ii.ravel()], 1)
    v = _sample(img, H, inner, half)
    parity = (np.floor(inner[:, 0]) + np.floor(inner[:, 1])).astype(int) % 2
    means = [np.nanmean(v[parity == p]) if np.any(~np.isnan(v[parity == p])) else np.nan
             for p in (0, 1)]  # fmt: skip
    if np.isnan(means).any() or abs(means[0] - means[1]) < 10:
        return ""  # too little of the board in view to judge its border
    sides = {
        "first row's": [(j + 0.5, -0.5) for j in range(-1, cols)],
        "last row's": [(j + 0.5, rows - 0.5) for j in range(-1, cols)],
        "first column's": [(-0.5, i + 0.5) for i in range(-1, rows)],
        "last column's": [(cols - 0.5, i + 0.5) for i in range(-1, rows)],
    }
    for name, c in sides.items():
        c = np.array(c)
        s = _sample(img, H, c, half)
        ok = ~np.isnan(s)
        if ok.sum() < 3:
            continue
        p = (np.floor(c[:, 0]) + np.floor(c[:, 1])).astype(int) % 2
        nearest = np.where(np.abs(s - means[0]) <= np.abs(s - means[1]), 0, 1)
        if float(np.mean(nearest[ok] == p[ok])) < MIN_BORDER_SHARE:
            return name
    return ""
