"""The head's calibration row of a referenced stop: through the hole and the markers of the same
pair, checked against the error a head really off by one sigma gives."""

from __future__ import annotations

import numpy as np

from cell.referencing import resect
from cell.referencing.head_term import referenced_head_covariance, used_view
from cell.referencing.layout import stop_pose
from cell.referencing.synthetic import observe
from cell.uncertainty.calibration import (
    N_PARAMETERS,
    algebraic_circle,
    jacobian_covariance,
    perturbed,
    pixel_pairs,
    retriangulate,
)
from measure.calibration_uncertainty import CalibrationUncertainty


def _only(index: int, sigma: float) -> CalibrationUncertainty:
    """An uncertainty of one parameter (:data:`PARAMETER_NAMES` order) alone."""
    s = np.zeros(N_PARAMETERS)
    s[index] = sigma
    return CalibrationUncertainty(s[0:4], s[4:9], s[9:13], s[13:18], s[18:21], s[21:24], 0.0)


def test_the_head_row_is_the_error_a_head_off_by_one_sigma_gives(small_cell, stereo,
                                                                 marker_truth):  # fmt: skip
    """The true head has its left cx (or its rig's rotation about y) one sigma off; the stop's
    markers and the hole's rim are seen through it and measured with the nominal head. The hole's
    error in the cell is what the row states, and a small part of what the same error does when
    the arm carries the camera frame (the plain row)."""
    T = stop_pose(small_cell, stereo, "PVL")
    ids, P = marker_truth.ids, marker_truth.true
    phi = np.linspace(0, 2 * np.pi, 90, endpoint=False)
    rim_left = np.column_stack([4e-3 * np.cos(phi), 4e-3 * np.sin(phi), np.full_like(phi, 0.25)])
    for index, sigma in ((2, 0.05), (19, 2e-5)):  # left.cx (px), rvec.y (rad)
        true_head = perturbed(stereo, np.eye(N_PARAMETERS)[index] * sigma)
        view = observe(marker_truth, true_head, T, "PVL", 0.0, np.random.default_rng(0), T)
        r = resect(view, stereo, ids, P, None, 0.05)
        px_l, px_r = pixel_pairs(true_head, rim_left)
        c = algebraic_circle(retriangulate(stereo, px_l, px_r))[:3]
        error = r.T_cell_left[:3, :3] @ c + r.T_cell_left[:3, 3] - (T[:3, :3] @ [0, 0, 0.25]
                                                                     + T[:3, 3])  # fmt: skip
        pts = retriangulate(stereo, px_l, px_r)
        cov = referenced_head_covariance(stereo, _only(index, sigma), used_view(view, r.used),
                                         ids, P, r.T_cell_left, pts)  # fmt: skip
        assert cov is not None
        stated = np.sqrt(np.trace(cov))
        assert abs(np.linalg.norm(error) - stated) < 0.02 * stated
        plain = np.sqrt(np.trace(jacobian_covariance(stereo, pts, _only(index, sigma))[:3, :3]))
        assert stated < 0.5 * plain
