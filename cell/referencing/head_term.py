"""The head's calibration error at a referenced stop, through the hole AND the markers of the
same pair.

Without referencing the head's calibration moves a hole within the left camera frame, and the
arm carries that frame into the part: the budget's ``stereo_calibration`` row
(:func:`cell.uncertainty.calibration.jacobian_covariance`). At a referenced stop the left camera
frame is itself measured by the same head, from the markers around the hole: a focal length,
principal point or rig error that moves the hole in the camera frame moves the resected camera
with it, and the two largely cancel in the cell frame. Counted as if the arm had carried the
frame, the row was the largest of a referenced hole's budget (about 1.1 um against 0.2-0.7 um
for the others, demo seed 1) while the truth fell within U for every characteristic.

:func:`referenced_head_covariance` propagates each of the 24 parameters (``+-1 sigma``, central
differences, as :func:`~cell.uncertainty.calibration.jacobian_covariance`) through both: the
hole's edge points re-triangulated and its circle refitted in the changed head, the stop
resected again from the same marker pixels with the changed head (to first order: one
Gauss-Newton step, :func:`cell.referencing.resection.pose_sensitivity`), and the centre carried
into the cell. The parameters are taken as independent, as the head's file states them.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from cell.referencing.observations import MarkerView
from cell.referencing.resection import pose_sensitivity
from cell.uncertainty.calibration import (
    MAX_JACOBIAN_POINTS,
    N_PARAMETERS,
    algebraic_circle,
    parameter_sigmas,
    perturbed,
    pixel_pairs,
    retriangulate,
)
from measure import StereoCalibration
from measure.calibration_uncertainty import CalibrationUncertainty

Array = NDArray[np.float64]


def referenced_head_covariance(
    stereo: StereoCalibration,
    unc: CalibrationUncertainty,
    view: MarkerView,
    marker_ids: tuple[str, ...],
    positions_cell: Array,
    T_cell_left: Array,
    points_left_m: Array,
) -> Array:
    """The covariance (3, 3) m², cell frame, of a referenced hole's centre from the head's
    calibration uncertainty ``unc`` (module doc). ``view``: the stop's markers (only those the
    resection used); ``T_cell_left``: its resected pose; ``points_left_m``: the hole's inlier
    edge points (left frame, m)."""
    pts = np.asarray(points_left_m, float)
    if len(pts) > MAX_JACOBIAN_POINTS:
        pts = pts[np.linspace(0, len(pts) - 1, MAX_JACOBIAN_POINTS).round().astype(int)]
    px_l, px_r = pixel_pairs(stereo, pts)
    sig = parameter_sigmas(unc)
    free = np.flatnonzero(sig > 0)
    heads = [stereo]
    for i in free:
        e = np.zeros(N_PARAMETERS)
        e[i] = sig[i]
        heads += [perturbed(stereo, e), perturbed(stereo, -e)]
    poses = pose_sensitivity(view, marker_ids, positions_cell, T_cell_left, heads)
    cols = []
    for k in range(len(free)):
        ends = []
        for head, T in zip(heads[1 + 2 * k : 3 + 2 * k], poses[1 + 2 * k : 3 + 2 * k],
                           strict=True):  # fmt: skip
            c = algebraic_circle(retriangulate(head, px_l, px_r))[:3]
            ends.append(T[:3, :3] @ c + T[:3, 3])
        cols.append(0.5 * (ends[0] - ends[1]))
    if not cols:
        return np.zeros((3, 3))
    J = np.column_stack(cols)
    return J @ J.T


def used_view(view: MarkerView, used: tuple[str, ...]) -> MarkerView:
    """``view`` with only the markers in ``used`` (a resection's)."""
    keep = set(used)
    return MarkerView(view.view_id, {m: uv for m, uv in view.uv_left.items() if m in keep},
                      {m: uv for m, uv in view.uv_right.items() if m in keep},
                      view.T_cell_left_prior)  # fmt: skip
