"""The calibration tour's predicted σ against the adjustment itself on simulated data.

The views of a design are simulated with a drawn truth (``cell.calibration.estimate.synthetic``),
solved by ``cell.calibration.estimate.solve`` and the errors against the truth (in the adjustment's
gauge) divided by the predicted σ: they should scatter with unit RMS.
"""

from __future__ import annotations

import numpy as np
import pytest

from cell.calibration.estimate import (
    Cameras,
    SolveOptions,
    parameter_errors,
    random_truth,
    simulate,
    solve_calibration,
    truth_in_gauge,
)
from cell.calibration.plan import (
    TargetGeometry,
    board_of,
    design_rows,
    information_model,
    predict_sigmas,
    stereo_model,
)
from cell.camera import cell_stereo
from cell.config import load_builtin_cell
from planner.calibration import candidate_views
from robots.transforms import invert, make_transform, rpy_to_matrix

TARGET = TargetGeometry(
    "chessboard", 9, 7, 0.01, make_transform(rpy_to_matrix([np.pi, 0, 0]), [0.9, -0.45, 0.381])
)


def _normalised_errors(n_views: int, seeds: int, rep_m: float) -> np.ndarray:
    cell = load_builtin_cell()
    stereo = cell_stereo(cell)
    head = stereo_model(stereo)
    cands = candidate_views(cell.build_arm(), board_of(TARGET), head, 0.25, cell.home_q())
    cands = cands.subset(np.arange(0, len(cands), 4))
    stops = np.array([cell.home_q(), cell.home_q() + np.array([0.3, 0.2, -0.1, 0.4, 0.3, -0.5])])
    model = information_model(cell, TARGET, stereo, cands, stops, 0.1, rep_m)
    rows = design_rows(model, n_views, "tcp", [])
    sigma = predict_sigmas(model, rows)["sigma"]
    dh = cell.build_robot().dh
    X0 = cell.T_tool0_tcp() @ head.T_tcp_left
    Y0 = invert(cell.T_cell_base()) @ TARGET.T_cell_target
    options = SolveOptions(flange_scatter=rep_m > 0, flange_sigma_m=rep_m, flange_sigma_rad=0.0)
    z = []
    for seed in range(seeds):
        truth = random_truth(dh, Cameras.from_stereo(stereo), TARGET.spec(), X0, Y0, seed=seed)
        obs = simulate(truth, cands.q[rows], 0.1, seed + 100, flange_sigma_m=rep_m)
        result = solve_calibration(obs, dh, options)
        err = parameter_errors(result.calibration, truth_in_gauge(truth))
        assert set(err) == set(sigma)  # the adjustment frees what the prediction said
        z += [err[k] / sigma[k] for k in err]
    return np.array(z)


def test_predicted_sigma_is_the_adjustments_scatter() -> None:
    z = _normalised_errors(n_views=15, seeds=3, rep_m=0.0)
    assert 0.7 < np.sqrt(np.mean(z**2)) < 1.4


@pytest.mark.slow
def test_predicted_sigma_with_the_arms_repeatability() -> None:
    z = _normalised_errors(n_views=40, seeds=10, rep_m=11.06e-6)
    assert 0.8 < np.sqrt(np.mean(z**2)) < 1.25
    assert 0.9 <= np.mean(np.abs(z) < 2) <= 0.99
