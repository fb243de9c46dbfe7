"""The views' whitening: Omega^-1/2 of corner noise plus a per-view flange pose error."""

from __future__ import annotations

import numpy as np

from cell.calibration.estimate import ViewWhitening, white_covariance


def test_the_whitening_turns_omega_into_the_identity() -> None:
    rng = np.random.default_rng(0)
    n_per, V = 20, 3
    F = rng.normal(0, 1e3, (n_per * V, 6))
    rows_view = np.repeat(np.arange(V), n_per)
    s2, sm, sr = 0.01, 2e-5, 4e-5
    Sigma = np.diag([sm**2] * 3 + [sr**2] * 3)
    Omega = s2 * np.eye(n_per * V)
    for v in range(V):
        sel = rows_view == v
        Omega[np.ix_(sel, sel)] += F[sel] @ Sigma @ F[sel].T
    W = ViewWhitening(F, rows_view, s2, sm, sr)(np.eye(n_per * V))
    assert np.allclose(W @ Omega @ W.T, np.eye(n_per * V), atol=1e-9)
    assert np.allclose(W, W.T)  # the symmetric root


def test_corner_noise_alone_is_the_classical_covariance() -> None:
    rng = np.random.default_rng(1)
    J = rng.normal(size=(50, 4))
    r = rng.normal(size=50)
    cr = white_covariance(J, r)
    assert np.allclose(cr.covariance, (r @ r / 46) * np.linalg.inv(J.T @ J))
    assert cr.source == "not modelled" and cr.flange_sigma_m == 0.0
