"""robots.calibration: D-H error FK, the twist of each term, the structural redundancies."""

from __future__ import annotations

import numpy as np
import pytest

from robots.calibration import (
    calibrated_table,
    dh_error_twists,
    fk_with_errors,
    structural_redundancies,
    term_names,
)
from robots.calibration.redundancy import fold_redundant
from robots.dh import fk_dh
from robots.dh_models import dh_table

MODEL = "abb_irb2600_20_165"


def _twist_of(dT: np.ndarray, T: np.ndarray) -> np.ndarray:
    W = dT @ np.linalg.inv(T)
    return np.concatenate(
        [W[..., :3, 3], np.stack([W[..., 2, 1], W[..., 0, 2], W[..., 1, 0]], -1)], -1
    )


def test_zero_errors_are_the_nominal_kinematics_and_the_calibrated_table_agrees() -> None:
    t = dh_table(MODEL)
    rng = np.random.default_rng(0)
    q = rng.uniform(-1.5, 1.5, (20, 6))
    assert np.allclose(fk_with_errors(t, np.zeros(24), q), fk_dh(t, q), atol=1e-14)
    delta = rng.normal(0, 1e-3, 24)
    assert np.allclose(
        fk_dh(calibrated_table(t, delta), q), fk_with_errors(t, delta, q), atol=1e-14
    )


def test_each_twist_is_the_derivative_of_the_flange_pose() -> None:
    t = dh_table(MODEL)
    rng = np.random.default_rng(1)
    q = rng.uniform(-1.5, 1.5, (6, 6))
    delta = rng.normal(0, 1e-3, 24)
    T = fk_with_errors(t, delta, q)
    tw = dh_error_twists(t, delta, q)
    h = 1e-7
    for k in range(24):
        d2 = delta.copy()
        d2[k] += h
        num = _twist_of((fk_with_errors(t, d2, q) - T) / h, T)
        assert np.abs(num - tw[:, k]).max() < 1e-5, term_names()[k]


def test_structural_redundancies_of_an_abb_arm() -> None:
    red = structural_redundancies(dh_table(MODEL))
    assert set(red) == {"d1_m", "theta1_rad", "d3_m", "a6_m", "d6_m", "alpha6_rad", "theta6_rad"}
    assert "hand-eye" in red["d6_m"] and "base" in red["d1_m"] and "parallel" in red["d3_m"]


def test_after_the_structural_terms_the_rest_is_determined_by_full_poses() -> None:
    """With base and tool poses free, random 6-DOF flange poses determine every other term."""
    t = dh_table(MODEL)
    rng = np.random.default_rng(2)
    q = rng.uniform(-1.5, 1.5, (100, 6))
    T = fk_dh(t, q)
    tw = dh_error_twists(t, np.zeros(24), q)
    blocks = []
    for i in range(len(q)):
        R, p = T[i, :3, :3], T[i, :3, 3]
        P = np.array([[0, -p[2], p[1]], [p[2], 0, -p[0]], [-p[1], p[0], 0]])
        Ad = np.block([[R, P @ R], [np.zeros((3, 3)), R]])
        blocks.append(np.concatenate([tw[i].T, np.eye(6), Ad], axis=1))
    A = np.concatenate(blocks)
    names = [*term_names(), *[f"B{k}" for k in range(6)], *[f"E{k}" for k in range(6)]]
    red = structural_redundancies(t)
    keep = [i for i, n in enumerate(names) if n not in red]
    assert np.linalg.matrix_rank(A[:, keep] / np.linalg.norm(A[:, keep], axis=0), tol=1e-6) == len(
        keep
    )
    assert np.linalg.matrix_rank(A / np.linalg.norm(A, axis=0), tol=1e-6) == len(keep)


@pytest.mark.parametrize("seed", [0, 1])
def test_folding_the_redundant_terms_keeps_every_flange_pose(seed: int) -> None:
    t = dh_table(MODEL)
    rng = np.random.default_rng(seed)
    delta = rng.normal(0, 3e-4, 24)
    q = rng.uniform(-1.5, 1.5, (30, 6))
    folded, C, E = fold_redundant(t, delta)
    assert all(folded[term_names().index(n)] == 0.0 for n in structural_redundancies(t))
    err = np.abs(fk_with_errors(t, delta, q) - C @ fk_with_errors(t, folded, q) @ E).max()
    assert err < 5e-7  # d3 into d2 is exact to second order (alpha2 has an error)


def test_a_wrong_error_vector_is_refused() -> None:
    with pytest.raises(ValueError, match="24 finite"):
        fk_with_errors(dh_table(MODEL), np.zeros(23), np.zeros(6))
