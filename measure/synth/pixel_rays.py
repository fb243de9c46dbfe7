"""Per-pixel undistorted rays of a camera, computed once (band by band, as renders need them)
and cached.

Every pixel centre ``(u, v)`` of a camera maps to the ideal normalised image coordinates
``(x/z, y/z)`` of the ray it sees (OpenCV's ``undistortPoints``, iterated to 1e-12). A plane
seen by the camera is then a homography of these coordinates, so rendering a flat target needs
no lens model per view: the cache holds the exact rays of each camera (float32, below 2e-4 px
of rounding at 5 MP) for the few heads a run uses.
"""

from __future__ import annotations

import threading
from collections import OrderedDict

import numpy as np

from measure.calibration import StereoCalibration

#: how many cameras' rays are kept (a 2448 × 2048 camera holds 40 MB)
CACHE_CAMERAS = 4

_cache: OrderedDict[bytes, _Rays] = OrderedDict()
_lock = threading.Lock()


def pixel_rays_key(stereo: StereoCalibration, side: str) -> bytes:
    """What identifies camera ``side``'s rays: its intrinsics, distortion and image size."""
    K, d = (
        (stereo.K_left, stereo.dist_left) if side == "left" else (stereo.K_right, stereo.dist_right)
    )
    size = np.asarray(stereo.image_size, dtype=np.int64)
    return (
        b"|".join(np.ascontiguousarray(a, dtype=np.float64).tobytes() for a in (K, d))
        + size.tobytes()
    )


#: rows undistorted at a time: the rays are computed band by band, when a render first needs
#: them (a survey worker that renders one small view of the plate pays for its rows only)
BAND_ROWS = 64


class _Rays:
    """One camera's rays: full-size arrays filled band by band (each pixel's ray is the same
    whichever band computes it: OpenCV undistorts each point on its own)."""

    def __init__(self, stereo: StereoCalibration, side: str) -> None:
        w, h = stereo.image_size
        self._nx = np.empty((h, w), dtype=np.float32)
        self._ny = np.empty((h, w), dtype=np.float32)
        self.views = (self._nx.view(), self._ny.view())
        for a in self.views:
            a.setflags(write=False)
        self.done = np.zeros((h + BAND_ROWS - 1) // BAND_ROWS, dtype=bool)
        self.lock = threading.Lock()

    def fill(self, stereo: StereoCalibration, side: str, y0: int, y1: int) -> None:
        """Compute the bands holding rows ``[y0, y1)`` not computed yet."""
        w, h = stereo.image_size
        with self.lock:
            for b in range(max(y0, 0) // BAND_ROWS, (min(y1, h) + BAND_ROWS - 1) // BAND_ROWS):
                if self.done[b]:
                    continue
                r0, r1 = b * BAND_ROWS, min(h, (b + 1) * BAND_ROWS)
                vv, uu = np.mgrid[r0:r1, 0:w].astype(np.float64)
                n = stereo.normalized(np.stack([uu.ravel(), vv.ravel()], axis=1), side)
                self._nx[r0:r1] = n[:, 0].reshape(r1 - r0, w)
                self._ny[r0:r1] = n[:, 1].reshape(r1 - r0, w)
                self.done[b] = True


def pixel_rays(
    stereo: StereoCalibration, side: str, rows: tuple[int, int] | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Normalised ray coordinates ``(nx, ny)`` (each (h, w) float32, read-only) of every pixel
    centre of camera ``side`` ("left" or "right"); cached per camera model. ``rows`` =
    ``(y0, y1)``: only rows ``y0 <= y < y1`` need be valid (the others are computed when a
    later call asks for them)."""
    if side not in ("left", "right"):
        raise ValueError(f"side must be 'left' or 'right', got {side!r}")
    key = pixel_rays_key(stereo, side)
    with _lock:
        rays = _cache.get(key)
        if rays is not None:
            _cache.move_to_end(key)
        else:
            rays = _cache[key] = _Rays(stereo, side)
            while len(_cache) > CACHE_CAMERAS:
                _cache.popitem(last=False)
    y0, y1 = rows if rows is not None else (0, stereo.image_size[1])
    if y1 > y0:
        rays.fill(stereo, side, y0, y1)
    return rays.views
