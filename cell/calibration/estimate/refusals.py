"""Data sets that cannot determine the hand-eye, refused before any fit with one line why.

- too few views (``min_views``), or the target seen in too few of them (per camera);
- too little rotation between the views (``min_rotation_rad`` for the largest relative one);
- relative rotations about (near-)parallel axes: the hand-eye's translation along that axis
  is then undetermined (Tsai and Lenz 1989). The axes of all view pairs turning by at least
  ``min_rotation_rad`` are collected; their spread (the angle of the second principal
  direction, ``atan(sqrt(s2 / s1))``) must reach ``min_axis_spread_rad``.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from cell.calibration.errors import DegenerateCalibrationError
from cell.calibration.estimate.observations import CalibrationObservations

Array = NDArray[np.float64]


def rotation_axis_spread(T_base_tool0: Array, min_rotation_rad: float) -> tuple[float, float, int]:
    """``(largest relative rotation (rad), axis spread (rad), pairs used)`` of flange poses."""
    R = Rotation.from_matrix(T_base_tool0[:, :3, :3])
    V = len(T_base_tool0)
    i, j = np.triu_indices(V, 1)
    rel = (R[i].inv() * R[j]).as_rotvec()  # in tool0 of view i: the hand-eye sees these axes
    ang = np.linalg.norm(rel, axis=1)
    if len(ang) == 0:
        return 0.0, 0.0, 0
    use = ang >= min_rotation_rad
    if use.sum() < 2:
        return float(ang.max()), 0.0, int(use.sum())
    axes = rel[use] / ang[use, None]
    s = np.linalg.svd(axes, compute_uv=False)  # axis sign does not matter: second moments
    spread = float(np.arctan(np.sqrt(s[1] ** 2 / s[0] ** 2)))
    return float(ang.max()), spread, int(use.sum())


def check_views(
    obs: CalibrationObservations,
    T_base_tool0: Array,
    min_views: int,
    min_rotation_rad: float,
    min_axis_spread_rad: float,
) -> None:
    """Raise :class:`DegenerateCalibrationError` for a data set that cannot fix the hand-eye."""
    V = len(obs.views)
    if min_views > V:
        raise DegenerateCalibrationError(
            f"{V} view(s) in {obs.source}; at least {min_views} are needed"
        )
    sides = ("left", "right") if obs.cameras.stereo else ("left",)
    for side in sides:
        _c, seen = obs.corners(side)
        if side == "left" and seen.sum() < min_views:
            missing = [v.name for v, s in zip(obs.views, seen, strict=True) if not s]
            raise DegenerateCalibrationError(
                f"the target is seen in {int(seen.sum())} of {V} left images; at least "
                f"{min_views} are needed (not seen: {', '.join(missing[:5])})"
            )
        if side == "right" and 0 < seen.sum() < 2:
            raise DegenerateCalibrationError(
                f"the target is seen in only {int(seen.sum())} right image(s): too few for the "
                "stereo extrinsics"
            )
    _c, seen = obs.corners("left")
    largest, spread, pairs = rotation_axis_spread(T_base_tool0[seen], min_rotation_rad)
    if largest < min_rotation_rad:
        raise DegenerateCalibrationError(
            f"the views turn by at most {np.rad2deg(largest):.2f} deg between each other; at "
            f"least {np.rad2deg(min_rotation_rad):.1f} deg is needed"
        )
    if spread < min_axis_spread_rad:
        raise DegenerateCalibrationError(
            f"the relative rotations of the views are about (near-)parallel axes (spread "
            f"{np.rad2deg(spread):.2f} deg over {pairs} pairs, at least "
            f"{np.rad2deg(min_axis_spread_rad):.1f} deg is needed): the hand-eye is undetermined "
            "along that axis"
        )
