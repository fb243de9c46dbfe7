"""Random survey views of markers for the marker benchmark and tests: a grid of markers in front
of the head at one stand-off, each tilted at random, spaced so their labels never overlap."""

from __future__ import annotations

import math

import numpy as np

from measure.calibration import StereoCalibration
from measure.head import head_frame
from measure.markers.design import MarkerDesign
from measure.synth.marker_draw import MarkerPatch


def _tilted(tilt_rad: float, azimuth_rad: float) -> np.ndarray:
    """Head-frame unit normal: −z tilted by ``tilt_rad`` toward azimuth ``azimuth_rad``."""
    s = math.sin(tilt_rad)
    return np.array([s * math.cos(azimuth_rad), s * math.sin(azimuth_rad), -math.cos(tilt_rad)])


def marker_grid_view(
    stereo: StereoCalibration,
    rng: np.random.Generator,
    design: MarkerDesign,
    diameter_m: float,
    standoff_m: float,
    max_tilt_deg: float,
    max_markers: int = 9,
) -> list[MarkerPatch]:
    """Markers (LEFT camera frame) on a grid across the part of the view both cameras see at
    ``standoff_m`` (head z), each tilted by up to ``max_tilt_deg`` in a random direction, with
    random distinct codes and ``up`` directions."""
    half_x, half_y = 0.09 * standoff_m, 0.17 * standoff_m
    pitch = 2.2 * design.outer_radius(diameter_m)
    nx = max(1, min(3, int(2 * half_x / pitch) + 1))
    ny = max(1, min(3, int(2 * half_y / pitch) + 1))
    xs = np.linspace(-half_x, half_x, nx) if nx > 1 else np.zeros(1)
    ys = np.linspace(-half_y, half_y, ny) if ny > 1 else np.zeros(1)
    T = head_frame(stereo)
    codes = rng.choice(design.n_codes(), size=nx * ny, replace=False)
    out = []
    for k, (x, y) in enumerate((x, y) for x in xs for y in ys):
        if len(out) >= max_markers:
            break
        c_head = np.array([x, y, standoff_m])
        tilt = math.radians(max_tilt_deg) * math.sqrt(rng.uniform())
        n_head = _tilted(tilt, rng.uniform(0, 2 * np.pi))
        up_head = np.cross(n_head, [math.cos(a := rng.uniform(0, 2 * np.pi)), math.sin(a), 0.0])
        out.append(
            MarkerPatch(
                code=int(codes[k]),
                center_m=T[:3, :3] @ c_head + T[:3, 3],
                normal=T[:3, :3] @ n_head,
                diameter_m=diameter_m,
                up=T[:3, :3] @ up_head,
                design=design,
            )
        )
    return out
