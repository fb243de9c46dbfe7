"""How many orientations a set of calibration views holds, and how far apart they are.

The candidate views repeat each orientation at several distances and offsets (they help the
arm's scale), so the smallest rotation between two views is often 0: two views from one
direction. For the hand-eye only the rotations between orientations count, so a tour's summary
gives the number of distinct orientations and the smallest rotation between two of them.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

#: two views closer in rotation than this (rad) share an orientation
SAME_ORIENTATION_RAD = np.radians(1.0)


def orientation_figures(
    R: NDArray[np.float64], same_rad: float = SAME_ORIENTATION_RAD
) -> tuple[int, float | None]:
    """``(orientations, smallest rotation between two of them, rad)`` of rotations ``R``
    (n, 3, 3): views within ``same_rad`` of an earlier kept one share its orientation; the
    rotation is None for a single orientation (``caltour.json`` holds it: JSON has no NaN)."""
    kept: list[Rotation] = []
    for r in Rotation.from_matrix(np.asarray(R, dtype=float)):
        if all((k.inv() * r).magnitude() >= same_rad for k in kept):
            kept.append(r)
    gaps = [(a.inv() * b).magnitude() for i, a in enumerate(kept) for b in kept[i + 1 :]]
    return len(kept), float(min(gaps)) if gaps else None
