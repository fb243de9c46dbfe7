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
from measure.synth.marker_draw import MarkerPatch, draw_markers
from measure.synth.optics import ray_grid, vignetting
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


def _background(stereo: StereoCalibration, side: str, opts: RenderOptions) -> np.ndarray:
    """A dim, vignetted background (fraction of full scale, float32), at 16-px nodes."""
    w, h = stereo.image_size
    grid = ray_grid(stereo, side, 0.0, 0.0, w, h, 16.0)  # only its node positions are used
    rows, cols = grid.nx.shape
    gx = grid.x0 + 16.0 * np.arange(cols)
    gy = grid.y0 + 16.0 * np.arange(rows)
    K = stereo.K_left if side == "left" else stereo.K_right
    V = vignetting(gx[None, :], gy[:, None], K, stereo.image_size, opts.vignetting)
    small = (BACKGROUND * opts.surface / 0.62 * V).astype(np.float32)
    M = np.array([[1 / 16.0, 0.0, -grid.x0 / 16.0], [0.0, 1 / 16.0, -grid.y0 / 16.0]])
    flags = cv2.INTER_LINEAR | cv2.WARP_INVERSE_MAP
    return cv2.warpAffine(small, M, (w, h), flags=flags, borderMode=cv2.BORDER_REPLICATE)


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
        img = _background(stereo, side, opts)
        draw_markers(img, stereo, side, markers, opts.blur_sigma_px, opts.vignetting)
        out.append(_camera_output(img, opts, (0, 0, 0, 0), rng))
    return MarkerRender(left=out[0], right=out[1], markers=tuple(markers))
