"""Synthetic runs of the built-in frame for the gdt tests: a true part (in-plane scatter,
sizes in the middle of their limits), placed on the fixture by a given pose, measured with
isotropic noise stated as its covariance. A uniquely named module (imported by the tests)."""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from cell.records.hole_result import HoleResult

SIGMA_M = 8e-6


def placement(mm: float = 1.5, deg: float = 0.4) -> np.ndarray:
    """The part off its fixture by ``mm`` and ``deg`` in a fixed oblique direction (4x4)."""
    T = np.eye(4)
    axis = np.array([0.3, 0.5, 0.81]) / np.linalg.norm([0.3, 0.5, 0.81])
    T[:3, :3] = Rotation.from_rotvec(np.radians(deg) * axis).as_matrix()
    T[:3, 3] = mm * 1e-3 * np.array([0.8, -0.36, 0.48])
    return T


def truth(cell, seed: int) -> tuple[dict, dict]:
    """True centres (nominal part frame, m) and diameters: in-plane scatter of 15 um, sizes
    in the middle of their limits."""
    rng = np.random.default_rng(seed)
    cen, dia = {}, {}
    for h in cell.part.holes:
        n = np.asarray(h.normal)
        u = np.cross(n, [1.0, 0, 0] if abs(n[0]) < 0.9 else [0, 1.0, 0])
        u /= np.linalg.norm(u)
        du, dv = rng.normal(0, 15e-6, 2)
        cen[h.id] = np.asarray(h.position) + du * u + dv * np.cross(n, u)
        s = h.tolerances.size
        dia[h.id] = h.diameter + (s.upper_m + s.lower_m) / 2 + rng.normal(0, 3e-6)
    return cen, dia


def results(cell, cen: dict, dia: dict, T: np.ndarray, seed: int,
             missing: tuple[str, ...] = ()) -> list[HoleResult]:  # fmt: skip
    """A run's results: the true part placed by ``T`` on the fixture, each centre measured
    with isotropic noise of SIGMA_M (stated as its covariance), the diameter with 2 um."""
    rng = np.random.default_rng(seed + 1000)
    out = []
    for i, h in enumerate(cell.part.holes):
        base = dict(
            hole_id=h.id,
            stop_index=i,
            nominal_part_m=tuple(h.position),
            nominal_diameter_m=h.diameter,
            tolerance_m=None,
            decision_rule="iso14253",
        )
        if h.id in missing:
            out.append(HoleResult(status="missing", reason="no hole found: test", **base))
            continue
        c = T[:3, :3] @ (cen[h.id] + rng.normal(0, SIGMA_M, 3)) + T[:3, 3]
        out.append(HoleResult(
            status="ok", center_part_m=tuple(c), normal_part=tuple(T[:3, :3] @ h.normal),
            diameter_m=dia[h.id] + rng.normal(0, 2e-6), position_deviation_m=0.0,
            diameter_deviation_m=0.0, U_diameter_m=4e-6, rms_m=5e-6, passed=True,
            extra={"cov_center_part_m2": (np.eye(3) * SIGMA_M**2).tolist()}, **base))  # fmt: skip
    return out
