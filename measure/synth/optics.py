"""Camera optics for rendering: pixel → ray lookup grids, vignetting, optics blur."""

from __future__ import annotations

import threading
from collections import OrderedDict
from dataclasses import dataclass

import numpy as np

from measure.calibration import StereoCalibration
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
        """Normalised coordinates at pixel coordinates ``px``, ``py`` (float64 bilinear)."""
        fx = (np.asarray(px, dtype=np.float64) - self.x0) / self.step
        fy = (np.asarray(py, dtype=np.float64) - self.y0) / self.step
        rows, cols = self.nx.shape
        ix = np.clip(np.floor(fx).astype(np.int64), 0, cols - 2)
        iy = np.clip(np.floor(fy).astype(np.int64), 0, rows - 2)
        ax, ay = fx - ix, fy - iy
        out = []
        for grid in (self.nx, self.ny):
            g00, g01 = grid[iy, ix], grid[iy, ix + 1]
            g10, g11 = grid[iy + 1, ix], grid[iy + 1, ix + 1]
            out.append((g00 * (1 - ax) + g01 * ax) * (1 - ay) + (g10 * (1 - ax) + g11 * ax) * ay)
        return out[0], out[1]


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
_grids: OrderedDict[tuple, RayGrid] = OrderedDict()
_lock = threading.Lock()


def frame_ray_grid(stereo: StereoCalibration, side: str, step: float) -> RayGrid:
    """``ray_grid(stereo, side, 0, 0, w, h, step)`` over the whole image, cached per camera
    model (read-only arrays): every render of a camera asks for the same one."""
    w, h = stereo.image_size
    key = (pixel_rays_key(stereo, side), float(step))
    with _lock:
        hit = _grids.get(key)
        if hit is not None:
            _grids.move_to_end(key)
            return hit
    grid = ray_grid(stereo, side, 0.0, 0.0, w, h, step)
    grid.nx.setflags(write=False)
    grid.ny.setflags(write=False)
    with _lock:
        _grids[key] = grid
        while len(_grids) > CACHE_GRIDS:
            _grids.popitem(last=False)
    return grid


def vignetting(
    px: np.ndarray, py: np.ndarray, K: np.ndarray, image_size: tuple[int, int], strength: float
) -> np.ndarray:
    """Relative illumination ``1 - strength * (r / r_corner)^2`` at pixel coordinates."""
    w, h = image_size
    cx, cy = K[0, 2], K[1, 2]
    r_corner2 = max(cx, w - 1 - cx) ** 2 + max(cy, h - 1 - cy) ** 2
    return 1.0 - strength * ((px - cx) ** 2 + (py - cy) ** 2) / r_corner2
