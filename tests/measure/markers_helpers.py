"""Shared scenes of the marker tests: markers around a hole in front of the standard head."""

from __future__ import annotations

import numpy as np

from measure.markers import DEFAULT_DESIGN, MarkerDesign
from measure.synth import hole_in_view, standard_stereo
from measure.synth.markers import MarkerPatch


def ring_of_markers(
    codes: list[int],
    tilt_deg: float = 20.0,
    radius_m: float = 0.03,
    diameter_m: float = 0.005,
    design: MarkerDesign = DEFAULT_DESIGN,
) -> tuple[object, np.ndarray, np.ndarray, list[MarkerPatch]]:
    """``(stereo, hole centre, hole normal, markers)``: markers ``radius_m`` around a hole in its
    plane (LEFT camera frame)."""
    st = standard_stereo()
    c, n = hole_in_view(st, np.radians(tilt_deg))
    e1 = np.cross(n, [1.0, 0.0, 0.0])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(n, e1)
    angles = np.linspace(0.0, 2 * np.pi, len(codes), endpoint=False) + 0.3
    ms = [
        MarkerPatch(
            code=k,
            center_m=c + radius_m * (np.cos(a) * e1 + np.sin(a) * e2),
            normal=n,
            diameter_m=diameter_m,
            up=np.cos(a + 1.0) * e1 + np.sin(a + 1.0) * e2,
            design=design,
        )
        for k, a in zip(codes, angles, strict=True)
    ]
    return st, c, n, ms


def true_ideal_centre(st, m: MarkerPatch, side: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The marker's projected centre (ideal pixels), its centre and normal in camera ``side``."""
    C, N = np.asarray(m.center_m, float), np.asarray(m.normal, float)
    K = st.K_left
    if side == "right":
        C, N, K = st.R @ C + st.T, st.R @ N, st.K_right
    p = K @ C
    return p[:2] / p[2], C, N
