"""The background of a hole scene: the textured, vignetted surface without the hole, at half
resolution (the hole's window is rendered exactly by :mod:`measure.synth.render`). The
surface level times the vignetting is the same for every view of a camera: cached."""

from __future__ import annotations

import cv2
import numpy as np

from measure.calibration import StereoCalibration
from measure.synth.hole_scene import HoleGeometry, Shading
from measure.synth.lru import Lru
from measure.synth.optics import frame_ray_grid, vignetting
from measure.synth.pixel_rays import pixel_rays_key
from measure.synth.texture import TEXEL_M, sample_texture


def background(
    stereo: StereoCalibration, side: str, geo: HoleGeometry, sh: Shading, vig: float
) -> np.ndarray:
    """Textured, vignetted surface without the hole (fraction of full scale, float32).

    Computed at half resolution (pixel ``i`` of the half image is full pixel ``2i + 0.5``)
    and upsampled: the background only has to look right, the hole window is exact.
    """
    w, h = stereo.image_size
    step = 16.0
    grid = frame_ray_grid(stereo, side, step)
    x, y = geo.plane_hit(grid.nx, grid.ny)
    hw, hh = (w + 1) // 2, (h + 1) // 2
    M = np.array(
        [[2.0 / step, 0.0, (0.5 - grid.x0) / step], [0.0, 2.0 / step, (0.5 - grid.y0) / step]]
    )
    flags = cv2.INTER_LINEAR | cv2.WARP_INVERSE_MAP
    maps = [
        cv2.warpAffine(
            a.astype(np.float32), M, (hw, hh), flags=flags, borderMode=cv2.BORDER_REPLICATE
        )
        for a in ((x + sh.texture_offset[0]) / TEXEL_M, (y + sh.texture_offset[1]) / TEXEL_M)
    ]
    tex = sample_texture(maps[0], maps[1])
    half = _lit_half(stereo, side, sh.surface, vig) * (1.0 + sh.texture_amplitude * tex)
    return cv2.resize(half, (w, h), interpolation=cv2.INTER_LINEAR)


#: how many (camera, surface level, vignetting) half-resolution light maps are kept (5 MB each)
CACHE_LIGHT = 8
_light_maps = Lru(CACHE_LIGHT)


def _lit_half(stereo: StereoCalibration, side: str, surface: float, vig: float) -> np.ndarray:
    """``surface`` times the vignetting at the half-resolution background's pixels (float32,
    read-only; cached per camera: the same for every view)."""
    key = (pixel_rays_key(stereo, side), float(surface), float(vig))
    hit = _light_maps.lookup(key)
    if hit is not None:
        return hit
    w, h = stereo.image_size
    step = 16.0
    grid = frame_ray_grid(stereo, side, step)
    K = stereo.K_left if side == "left" else stereo.K_right
    gy, gx = np.mgrid[0 : grid.nx.shape[0], 0 : grid.nx.shape[1]]
    V = vignetting(grid.x0 + step * gx, grid.y0 + step * gy, K, stereo.image_size, vig)
    hw, hh = (w + 1) // 2, (h + 1) // 2
    M = np.array(
        [[2.0 / step, 0.0, (0.5 - grid.x0) / step], [0.0, 2.0 / step, (0.5 - grid.y0) / step]]
    )
    flags = cv2.INTER_LINEAR | cv2.WARP_INVERSE_MAP
    Vh = cv2.warpAffine(V.astype(np.float32), M, (hw, hh), flags=flags,
                        borderMode=cv2.BORDER_REPLICATE)  # fmt: skip
    lit = surface * Vh
    lit.setflags(write=False)
    return _light_maps.keep(key, lit)
