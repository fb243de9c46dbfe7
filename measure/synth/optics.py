"""Camera optics for rendering: pixel → ray lookup grids, vignetting, optics blur."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from measure.calibration import StereoCalibration
from measure.synth.lru import Lru
from measure.synth.pixel_rays import pixel_rays_key


@dataclass(frozen=True)
class RayGrid:
    """Exact normalised image coordinates (x/z, y/z) on a regular pixel grid.

    Nodes sit at pixel coordinates ``(x0 + i*step, y0 + j*step)``; between nodes the lens
    model is smooth enough that bilinear interpolation errs by well under 1e-4 px.
    """

    x0: float
    y0: float
    step: float
    nx: np.ndarray  # (rows, cols) normalised x
    ny: np.ndarray  # (rows, cols) normalised y

    def sample(self, px: np.ndarray, py: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Normalised coordinates at pixel coordinates ``px``, ``py`` (float64 bilinear; one
        compiled pass, the arithmetic of NumPy's version: the same values)."""
        px = np.ascontiguousarray(px, dtype=np.float64)
        py = np.ascontiguousarray(py, dtype=np.float64)
        ox, oy = np.empty(px.shape), np.empty(px.shape)
        _bilinear(self.nx, self.ny, float(self.x0), float(self.y0), float(self.step),
                  px.reshape(-1), py.reshape(-1), ox.reshape(-1), oy.reshape(-1))  # fmt: skip
        return ox, oy


@njit(cache=True)
def _bilinear(gnx, gny, x0, y0, step, px, py, ox, oy) -> None:
    """``ox[k], oy[k]``: the grids ``gnx``, ``gny`` (nodes at ``x0 + i step``, ``y0 + j step``)
    interpolated bilinearly at ``(px[k], py[k])``, clamped to the outer cells."""
    rows, cols = gnx.shape
    for k in range(px.shape[0]):
        fx = (px[k] - x0) / step
        fy = (py[k] - y0) / step
        ix = min(max(np.int64(math.floor(fx)), 0), cols - 2)
        iy = min(max(np.int64(math.floor(fy)), 0), rows - 2)
        ax, ay = fx - ix, fy - iy
        bx, by = 1 - ax, 1 - ay
        ox[k] = (gnx[iy, ix] * bx + gnx[iy, ix + 1] * ax) * by + (
            gnx[iy + 1, ix] * bx + gnx[iy + 1, ix + 1] * ax
        ) * ay
        oy[k] = (gny[iy, ix] * bx + gny[iy, ix + 1] * ax) * by + (
            gny[iy + 1, ix] * bx + gny[iy + 1, ix + 1] * ax
        ) * ay


def ray_grid(
    stereo: StereoCalibration, side: str, x0: float, y0: float, w: float, h: float, step: float
) -> RayGrid:
    """A :class:`RayGrid` covering pixels ``[x0, x0 + w] × [y0, y0 + h]`` (with one node margin)."""
    cols = int(np.ceil(w / step)) + 3
    rows = int(np.ceil(h / step)) + 3
    gx = x0 - step + step * np.arange(cols)
    gy = y0 - step + step * np.arange(rows)
    X, Y = np.meshgrid(gx, gy)
    norm = stereo.normalized(np.stack([X.ravel(), Y.ravel()], axis=1), side)
    return RayGrid(
        x0=float(gx[0]),
        y0=float(gy[0]),
        step=float(step),
        nx=norm[:, 0].reshape(rows, cols),
        ny=norm[:, 1].reshape(rows, cols),
    )


#: how many cameras' full-frame ray grids :func:`frame_ray_grid` keeps
CACHE_GRIDS = 8
_grids = Lru(CACHE_GRIDS)


def frame_ray_grid(stereo: StereoCalibration, side: str, step: float) -> RayGrid:
    """``ray_grid(stereo, side, 0, 0, w, h, step)`` over the whole image, cached per camera
    model (read-only arrays): every render of a camera asks for the same one."""
    w, h = stereo.image_size
    key = (pixel_rays_key(stereo, side), float(step))
    hit = _grids.lookup(key)
    if hit is not None:
        return hit
    grid = ray_grid(stereo, side, 0.0, 0.0, w, h, step)
    grid.nx.setflags(write=False)
    grid.ny.setflags(write=False)
    return _grids.keep(key, grid)


def vignetting(
    px: np.ndarray, py: np.ndarray, K: np.ndarray, image_size: tuple[int, int], strength: float
) -> np.ndarray:
    """Relative illumination ``1 - strength * (r / r_corner)^2`` at pixel coordinates."""
    w, h = image_size
    cx, cy = K[0, 2], K[1, 2]
    r_corner2 = max(cx, w - 1 - cx) ** 2 + max(cy, h - 1 - cy) ** 2
    return 1.0 - strength * ((px - cx) ** 2 + (py - cy) ** 2) / r_corner2
