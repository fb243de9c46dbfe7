"""Shared helpers of the measure tests: a small stereo head and quick renders."""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from measure.synth import (
    RenderOptions,
    StereoRender,
    hole_in_view,
    render_hole_pair,
    toed_in_stereo,
)


@lru_cache(maxsize=1)
def small_stereo():
    """The standard head's optics with a 640×512 sensor crop (fast renders)."""
    return toed_in_stereo(image_size=(640, 512))


def render(
    diameter_m: float = 0.008,
    tilt_deg: float = 10.0,
    seed: int = 0,
    options: RenderOptions | None = None,
    offset=(0.0, 0.0, 0.0),
    stereo=None,
) -> StereoRender:
    """One pair of a hole at the standoff, tilted by ``tilt_deg`` at a seeded azimuth."""
    st = stereo or small_stereo()
    az = np.random.default_rng(seed).uniform(0, 2 * np.pi)
    c, n = hole_in_view(st, np.deg2rad(tilt_deg), az, offset)
    return render_hole_pair(st, c, n, diameter_m, options, seed=seed)


def angle_deg(a: np.ndarray, b: np.ndarray) -> float:
    """Angle between two unit vectors (degrees)."""
    return float(np.rad2deg(np.arccos(np.clip(a @ b, -1.0, 1.0))))
