"""Travel-time costs: the closed form equals ruckig's rest-to-rest duration."""

from __future__ import annotations

import numpy as np
import ruckig

from planner.costs import CostTable, cost_matrix, rest_to_rest_time, travel_time

V = np.array([3.054, 3.054, 3.054, 6.283, 6.283, 8.727])
A = 2.5 * V
J = 25.0 * V


def _ruckig_duration(q0: np.ndarray, q1: np.ndarray) -> float:
    otg, inp, traj = ruckig.Ruckig(6), ruckig.InputParameter(6), ruckig.Trajectory(6)
    inp.max_velocity, inp.max_acceleration, inp.max_jerk = V, A, J
    inp.current_position, inp.target_position = q0, q1
    assert otg.calculate(inp, traj) == ruckig.Result.Working
    return traj.duration


def test_closed_form_matches_ruckig_in_every_regime() -> None:
    rng = np.random.default_rng(7)
    for scale in (1e-4, 1e-2, 0.2, 1.0, 4.0):  # jerk-only, trapezoid-acceleration, cruise
        for _ in range(60):
            q0 = rng.uniform(-3, 3, 6)
            q1 = q0 + rng.normal(0, scale, 6)
            assert abs(travel_time(q0, q1, V, A, J) - _ruckig_duration(q0, q1)) < 1e-9


def test_single_joint_regimes_meet_continuously() -> None:
    v, a, j = 3.0, 7.5, 75.0
    d_jerk = 2 * a**3 / j**2  # peak acceleration reaches a
    d_cruise = v * (v / a + a / j)  # peak velocity reaches v
    for d in (d_jerk, d_cruise):
        lo, hi = rest_to_rest_time(np.array([d - 1e-9, d + 1e-9]), v, a, j)
        assert abs(hi - lo) < 1e-6
    t = rest_to_rest_time(np.linspace(0.0, 6.0, 2001), v, a, j)
    assert t[0] == 0.0 and np.all(np.diff(t) > 0)


def test_cost_matrix_and_table_agree_with_pairwise_times() -> None:
    rng = np.random.default_rng(3)
    X, Y = rng.uniform(-3, 3, (30, 6)), rng.uniform(-3, 3, (20, 6))
    M = cost_matrix(X, Y, V, A, J)
    assert M.shape == (30, 20)
    assert abs(M[4, 7] - travel_time(X[4], Y[7], V, A, J)) < 1e-12
    table = CostTable(V, A, J, span_rad=np.full(6, 14.0))
    assert np.max(np.abs(table.matrix(X, Y) - M)) < 1e-3
    assert np.allclose(M, cost_matrix(Y, X, V, A, J).T)  # symmetric


def test_cost_table_is_made_once_per_set_of_limits() -> None:
    from planner.costs import cost_table

    span = np.full(6, 14.0)
    t1 = cost_table(V, A, J, span)
    assert cost_table(V.copy(), A, J, span) is t1  # equal limits: the same table
    other = cost_table(V * 0.5, A, J, span)
    assert other is not t1
    q = np.random.default_rng(2).uniform(-3, 3, (30, 6))
    assert np.array_equal(t1.matrix(q, q), CostTable(V, A, J, span).matrix(q, q))
    assert not np.array_equal(other.matrix(q, q), t1.matrix(q, q))
