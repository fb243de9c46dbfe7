"""Closed-form IK: every branch, 2*pi alternatives, limits, reasons; checked numerically."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import least_squares
from scipy.spatial.transform import Rotation

from robots import MODELS, Arm, dh_table, fk_dh, solve_ik
from robots.ik import _wrist_solutions
from robots.transforms import make_transform

NAMES = sorted(MODELS)


def _pose_error(q: np.ndarray, table, T_target: np.ndarray) -> np.ndarray:
    T = fk_dh(table, q)
    rot = Rotation.from_matrix(T_target[:3, :3].T @ T[:3, :3]).as_rotvec()
    return np.concatenate([T[:3, 3] - T_target[:3, 3], 0.3 * rot])


def _numerical_solutions(table, T_target, lower, upper, starts: int, seed: int) -> np.ndarray:
    """Dense multi-start least squares over the joint box; converged solutions only."""
    rng = np.random.default_rng(seed)
    found = []
    for q0 in rng.uniform(lower, upper, (starts, 6)):
        res = least_squares(
            _pose_error,
            q0,
            args=(table, T_target),
            bounds=(lower, upper),
            xtol=1e-15,
            ftol=1e-15,
            gtol=1e-15,
        )
        if np.linalg.norm(res.fun) < 1e-10:
            found.append(res.x)
    return np.array(found)


@pytest.mark.parametrize("name", NAMES)
def test_round_trip_returns_the_configuration(name: str) -> None:
    spec = MODELS[name]
    table = dh_table(name)
    lower, upper = spec.limits()
    rng = np.random.default_rng(11)
    for q in rng.uniform(lower, upper, (100, 6)):
        result = solve_ik(table, fk_dh(table, q), lower, upper)
        assert result.ok, result.reason
        assert np.abs(result.solutions - q).max(axis=1).min() < 1e-7
        T = fk_dh(table, result.solutions)
        assert np.abs(T[:, :3, 3] - fk_dh(table, q)[:3, 3]).max() < 1e-9
        assert np.all(result.solutions >= lower) and np.all(result.solutions <= upper)


@pytest.mark.parametrize(
    ("name", "starts"),
    [(n, 20) for n in NAMES] + [pytest.param(n, 40, marks=pytest.mark.slow) for n in NAMES],
)
def test_every_branch_found_by_numerical_search(name: str, starts: int) -> None:
    spec = MODELS[name]
    table = dh_table(name)
    lower, upper = spec.limits()
    rng = np.random.default_rng(5)
    for trial, q in enumerate(rng.uniform(lower, upper, (2, 6))):
        T = fk_dh(table, q)
        analytic = solve_ik(table, T, lower, upper).solutions
        numeric = _numerical_solutions(table, T, lower, upper, starts=starts, seed=trial)
        assert len(numeric) > 0
        for qn in numeric:
            # every numerically found solution is one of the closed-form ones (same joint values)
            assert np.abs(analytic - qn).max(axis=1).min() < 1e-6


def test_two_pi_alternatives_of_j4_and_j6() -> None:
    arm = Arm()
    q = np.array([0.2, 0.1, -0.3, 0.4, 0.6, -0.5])
    sols = arm.ik(arm.fk(q)).solutions
    # J4 and J6 have +-400 deg: the same pose with J4 + 2pi, J6 - 2pi, both is there
    for d4, d6 in (
        (2 * np.pi, 0),
        (0, -2 * np.pi),
        (2 * np.pi, 2 * np.pi),
        (-2 * np.pi, 2 * np.pi),
    ):
        alt = q + np.array([0, 0, 0, d4, 0, d6])
        assert np.abs(sols - alt).max(axis=1).min() < 1e-9
    branch_ids = set(arm.ik(arm.fk(q)).branches.tolist())
    assert len(branch_ids) >= 4


def test_narrow_limits_drop_solutions_and_say_why() -> None:
    spec = MODELS["abb_irb2600_20_165"]
    table = dh_table(spec)
    lower, upper = spec.limits()
    q = np.array([0.2, 0.1, -0.3, 0.4, 0.6, -0.5])
    T = fk_dh(table, q)
    full = solve_ik(table, T, lower, upper)
    tight_lower, tight_upper = lower.copy(), upper.copy()
    tight_lower[4], tight_upper[4] = 0.7, 1.0  # J5 window excluding 0.6 and -0.6
    narrowed = solve_ik(table, T, tight_lower, tight_upper)
    assert full.ok and not narrowed.ok
    assert narrowed.reason == "outside limits"


def test_out_of_reach_and_singular_wrist() -> None:
    arm = Arm()
    far = make_transform(np.eye(3), [3.0, 0.0, 1.0])
    assert arm.ik(far).reason == "out of reach"
    q = np.array([0.3, 0.2, -0.1, 0.5, 0.0, 0.2])  # J5 = 0: J4 and J6 axes line up
    result = arm.ik(arm.fk(q))
    # that arm branch has a continuum of J4/J6 and is left out; the other arm branches stay
    assert result.n_branches == 6
    assert np.abs(np.sin(result.solutions[:, 4])).min() > 1e-6
    assert np.abs(result.solutions[:, :3] - q[:3]).max(axis=1).min() > 1e-3
    # J1 = 0, J2 + J3 = pi/2: the forearm points down, so a tool0 facing down is wrist-singular
    assert _wrist_solutions(0.0, np.pi / 2, [[1, 0, 0], [0, -1, 0], [0, 0, -1]]) == []
    above = make_transform(Rotation.from_euler("y", np.pi).as_matrix(), [0.0, 0.0, 1.5])
    assert arm.ik(above).reason == "shoulder singular"


def test_many_poses_solve_as_one_at_a_time_bit_for_bit() -> None:
    """``Arm.ik_many`` gives each pose ``Arm.ik``'s result, the same bits and reasons: random
    reachable poses (several branches), out of reach, a singular wrist, shoulder singular,
    and solutions outside narrowed limits."""
    arm = Arm()
    rng = np.random.default_rng(7)
    poses = [arm.fk(q) for q in rng.uniform(arm.lower, arm.upper, (60, 6))]
    poses += [
        make_transform(np.eye(3), [3.0, 0.0, 1.0]),
        arm.fk(np.array([0.3, 0.2, -0.1, 0.5, 0.0, 0.2])),
        make_transform(Rotation.from_euler("y", np.pi).as_matrix(), [0.0, 0.0, 1.5]),
    ]
    P = np.array(poses)
    many = arm.ik_many(P)
    one = [arm.ik(T) for T in P]
    reasons = {r.reason for r in one}
    assert {None, "out of reach", "shoulder singular"} <= reasons
    assert len(many) == len(one)
    for a, b in zip(many, one, strict=True):
        assert np.array_equal(a.solutions, b.solutions) and a.solutions.dtype == b.solutions.dtype
        assert np.array_equal(a.branches, b.branches)
        assert (a.reason, a.n_branches) == (b.reason, b.n_branches)
    arm.lower[4], arm.upper[4] = 0.7, 1.0  # a J5 window: most solutions leave the limits
    many, one = arm.ik_many(P), [arm.ik(T) for T in P]
    assert "outside limits" in {r.reason for r in one}
    for a, b in zip(many, one, strict=True):
        assert np.array_equal(a.solutions, b.solutions) and (a.reason, a.n_branches) == (
            b.reason,
            b.n_branches,
        )
