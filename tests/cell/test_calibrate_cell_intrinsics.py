"""The adjustment with the cameras' intrinsic corrections (``SolveOptions.estimate_intrinsics``):
on simulated data whose true head is off its stereo calibration by a few pixels of focal length
and principal point, the corrections are found within their stated sigma and the hand-eye is
no longer biased by them."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from cell.calibration.estimate import (
    Cameras,
    SolveOptions,
    corrected,
    example_truth,
    pose_error,
    reference_joints,
    simulate,
    solve_calibration,
    truth_in_gauge,
    view_joints,
)

#: the true head's corrections: per camera fx, fy, cx, cy (px), k1, k2, p1, p2, k3
TRUE_CORRECTION = np.array(
    [
        3.0,
        -2.0,
        1.5,
        -2.5,
        2e-3,
        -1e-3,
        0.0,
        0.0,
        0.0,
        -2.0,
        2.5,
        -1.0,
        2.0,
        -1e-3,
        0.0,
        0.0,
        0.0,
        0.0,
    ]
)
N = len(TRUE_CORRECTION) // 2


def _data(seed: int, n_views: int = 16):
    tr = example_truth(seed)
    cams = tr.cameras
    true_cams = Cameras(
        left=corrected(cams.left, TRUE_CORRECTION[:N]),
        right=corrected(cams.right, TRUE_CORRECTION[N:]),
        T_left_right=cams.T_left_right,
        source="true head",
    )
    Q = view_joints(replace(tr, cameras=true_cams), 3 * n_views, (0.2, 0.32), reference_joints(tr),
                    seed=seed)  # fmt: skip
    obs = simulate(replace(tr, cameras=true_cams), Q, 0.1, seed=seed)
    seen = [i for i, v in enumerate(obs.views) if v.corners_left_px is not None
            and v.corners_right_px is not None][:n_views]  # fmt: skip
    obs = replace(obs, views=tuple(obs.views[i] for i in seen), cameras=cams)
    return tr, obs


@pytest.mark.parametrize("seed", [0, 1])
def test_intrinsic_corrections_are_found_and_remove_the_bias(seed: int) -> None:
    tr, obs = _data(seed)
    truth = truth_in_gauge(tr)
    fixed = solve_calibration(obs, tr.dh)
    est = solve_calibration(obs, tr.dh, SolveOptions(estimate_intrinsics=True))
    values = np.array([v for v, _s in est.intrinsics.values()])
    sigmas = np.array([s for _v, s in est.intrinsics.values()])
    assert len(values) == 2 * N and np.all(sigmas > 0)
    assert np.all(np.abs(values - TRUE_CORRECTION) < 4 * sigmas + 0.05), (values, sigmas)
    dp_f, _ = pose_error(fixed.calibration.T_tool0_camera.T, truth.T_tool0_camera)
    dp_e, _ = pose_error(est.calibration.T_tool0_camera.T, truth.T_tool0_camera)
    assert dp_e < dp_f, (dp_e, dp_f)
    # the file keeps its layout: the corrections are marginalised, named in the notes
    assert not any(n.startswith("intrinsics.") for n in est.calibration.parameter_names)
    assert any("intrinsics corrected" in n for n in est.calibration.notes)
    p = len(est.calibration.parameter_names)
    assert est.calibration.covariance.shape == (p, p)
