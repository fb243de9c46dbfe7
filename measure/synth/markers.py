"""Rendering reference markers: in hole scenes (``render_hole_pair(..., markers=...)``) and in
survey views (:func:`render_markers_pair`: markers over a dim background, no hole).

Markers are drawn by :mod:`measure.synth.marker_draw` (exact-area edges through the lens model,
the optics blur); the camera's noise and quantisation are those of
:func:`measure.synth.render.render_hole_pair` (:class:`RenderOptions`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import cv2
import numpy as np

from measure.calibration import StereoCalibration
from measure.synth.lru import Lru
from measure.synth.marker_draw import MarkerPatch, draw_markers
from measure.synth.optics import vignetting
from measure.synth.pixel_rays import pixel_rays_key
from measure.synth.render import RenderOptions, _camera_output

__all__ = ["MarkerPatch", "MarkerRender", "render_markers_pair"]

#: reflectance of the survey view's background (a dim, matt fixture and table)
BACKGROUND = 0.22


@dataclass(frozen=True)
class MarkerRender:
    """A survey pair (``uint8``/``uint16``, like :class:`StereoRender`) and the markers in it."""

    left: np.ndarray
    right: np.ndarray
    markers: tuple[MarkerPatch, ...]


#: how many survey backgrounds (camera, surface level, vignetting) are kept (20 MB each at 5 MP)
CACHE_BACKGROUNDS = 4
_backgrounds = Lru(CACHE_BACKGROUNDS)


def _background(stereo: StereoCalibration, side: str, opts: RenderOptions) -> np.ndarray:
    """A dim, vignetted background (fraction of full scale, float32, read-only), at 16-px nodes
    (those of :func:`measure.synth.optics.ray_grid` over the image); cached per camera and
    levels: every survey view of a camera has the same."""
    key = (pixel_rays_key(stereo, side), float(opts.surface), float(opts.vignetting))
    hit = _backgrounds.lookup(key)
    if hit is not None:
        return hit
    w, h = stereo.image_size
    step = 16.0
    cols, rows = int(np.ceil(w / step)) + 3, int(np.ceil(h / step)) + 3
    x0, y0 = float(0.0 - step), float(0.0 - step)  # the grid's first node
    gx = x0 + 16.0 * np.arange(cols)
    gy = y0 + 16.0 * np.arange(rows)
    K = stereo.K_left if side == "left" else stereo.K_right
    V = vignetting(gx[None, :], gy[:, None], K, stereo.image_size, opts.vignetting)
    small = (BACKGROUND * opts.surface / 0.62 * V).astype(np.float32)
    M = np.array([[1 / 16.0, 0.0, -x0 / 16.0], [0.0, 1 / 16.0, -y0 / 16.0]])
    flags = cv2.INTER_LINEAR | cv2.WARP_INVERSE_MAP
    img = cv2.warpAffine(small, M, (w, h), flags=flags, borderMode=cv2.BORDER_REPLICATE)
    img.setflags(write=False)
    return _backgrounds.keep(key, img)


def render_markers_pair(
    stereo: StereoCalibration,
    markers: Sequence[MarkerPatch],
    options: RenderOptions | None = None,
    seed: int = 0,
) -> MarkerRender:
    """A survey view: the left and right images of ``markers`` (LEFT camera frame) over a dim
    uniform background, with the optics blur, noise and quantisation of ``options``."""
    opts = options or RenderOptions()
    if opts.bit_depth not in (8, 12):
        raise ValueError(f"bit_depth must be 8 or 12, got {opts.bit_depth}")
    rng = np.random.default_rng(seed)
    out = []
    for side in ("left", "right"):
        img = _background(stereo, side, opts).copy()
        draw_markers(img, stereo, side, markers, opts.blur_sigma_px, opts.vignetting)
        out.append(_camera_output(img, opts, (0, 0, 0, 0), rng))
    return MarkerRender(left=out[0], right=out[1], markers=tuple(markers))
