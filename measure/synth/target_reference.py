"""The reference (brute-force) calibration plate renderer: point samples per pixel.

This is the renderer :mod:`measure.synth.targets` replaced (kept as the slow reference the
tests and ``benchmarks/render_speed.py`` compare against): every pixel's plate point comes
from a 4-px grid of undistorted rays (bilinear between nodes), the pattern is point-sampled
``supersample``² times per pixel, then vignetting, a Gaussian optics blur and read noise.
A large ``supersample`` approximates the pixel's area integral that the fast renderer
computes analytically.
"""

from __future__ import annotations

import cv2
import numpy as np

from measure.calibration import StereoCalibration
from measure.synth.optics import RayGrid, ray_grid, vignetting
from measure.synth.targets import TargetRender
from measure.target import TargetSpec


def _pattern(spec: TargetSpec, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Reflectance (0 black … 1 white) at plate coordinates (metres)."""
    s = spec.pitch_m
    if spec.kind == "chessboard":
        # inner corners at (j s, i s); the squares span -s .. cols·s by -s .. rows·s
        inside = (x > -s) & (x < spec.cols * s) & (y > -s) & (y < spec.rows * s)
        black = (np.floor(x / s) + np.floor(y / s)) % 2 == 0
        val = np.where(inside & black, 0.08, 0.92)
    else:
        i = np.clip(np.round(y / s), 0, spec.rows - 1)
        shift = (i % 2) * s
        j = np.clip(np.round((x - shift) / (2 * s)), 0, spec.cols - 1)
        d2 = (x - shift - 2 * s * j) ** 2 + (y - s * i) ** 2
        val = np.where(d2 < (spec.circle_diameter_frac * s / 2) ** 2, 0.08, 0.92)
    lo, hi = spec.plate_bounds()
    on_plate = (x > lo[0]) & (x < hi[0]) & (y > lo[1]) & (y < hi[1])
    return np.where(on_plate, val, 0.25)


def _render_side(stereo, side, R, t, spec, blur, noise, supersample, rng) -> np.ndarray:
    """Plate coordinates are exact at 4-px grid nodes and bilinear between (smooth map)."""
    w, h = stereo.image_size
    grid = ray_grid(stereo, side, 0.0, 0.0, w, h, 4.0)
    d = np.stack([grid.nx, grid.ny, np.ones_like(grid.nx)], axis=-1)
    n = R[:, 2]
    X = d * ((n @ t) / (d @ n))[..., None] - t
    plate = RayGrid(grid.x0, grid.y0, grid.step, X @ R[:, 0], X @ R[:, 1])
    s = supersample
    offs = (np.arange(s) + 0.5) / s - 0.5
    acc = np.zeros((h, w))
    py, px = np.mgrid[0:h, 0:w].astype(np.float64)
    for dy in offs:
        for dx in offs:
            acc += _pattern(spec, *plate.sample(px + dx, py + dy))
    K = stereo.K_left if side == "left" else stereo.K_right
    img = (acc / (s * s)) * vignetting(px, py, K, stereo.image_size, 0.2)
    img = img.astype(np.float32)
    if blur > 0:
        img = cv2.GaussianBlur(img, (0, 0), blur)
    img = img * 255.0 + noise * rng.standard_normal(img.shape).astype(np.float32)
    return np.clip(img + 0.5, 0, 255).astype(np.uint8)


def render_target_pair_reference(
    stereo: StereoCalibration,
    spec: TargetSpec,
    T_left_plate: np.ndarray,
    blur_sigma_px: float = 0.7,
    noise_dn: float = 2.0,
    supersample: int = 2,
    seed: int = 0,
) -> TargetRender:
    """Render a calibration plate at ``T_left_plate`` (plate frame: pattern in z = 0).

    Same arguments and result as :func:`measure.synth.targets.render_target_pair`; costs
    about ``supersample``² ray casts per pixel (seconds per view at full resolution).
    """
    rng = np.random.default_rng(seed)
    T = np.asarray(T_left_plate, dtype=float)
    left = _render_side(
        stereo, "left", T[:3, :3], T[:3, 3], spec, blur_sigma_px, noise_dn, supersample, rng
    )
    T_right = np.eye(4)
    T_right[:3, :3], T_right[:3, 3] = stereo.R, stereo.T
    Tr = T_right @ T
    right = _render_side(
        stereo, "right", Tr[:3, :3], Tr[:3, 3], spec, blur_sigma_px, noise_dn, supersample, rng
    )
    return TargetRender(left=left, right=right, T_left_plate=T)
