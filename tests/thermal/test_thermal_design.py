"""The reference plan designed for the tour: better than the old plan, a local optimum, reachable
views, and a prediction that matches simulated identifications."""

from __future__ import annotations

import numpy as np
import pytest

from robots.design import choose_by_information, design_value
from robots.dh import fk_dh
from robots.models import MODELS
from robots.thermal import (
    CellGeometry,
    DriftSettings,
    DriftTruth,
    ThermalSpec,
    WarmUp,
    identify,
    reference_from_cold,
    simulate_observations,
)
from robots.thermal.design import (
    DesignOptions,
    candidate_views,
    design_views,
    evaluate,
    tcp_sensitivity,
)
from robots.thermal.plan import view_plan

SPEC = MODELS["abb_irb2600_20_165"]
STANDOFF_M = 0.25
#: a generated cell: two targets low in front of the arm, normals up (cell frame, m)
TARGETS = {
    "A": (np.array([0.95, -0.55, 0.35]), np.array([0.0, 0.0, 1.0])),
    "B": (np.array([0.95, 0.55, 0.35]), np.array([0.0, 0.0, 1.0])),
}


@pytest.fixture(scope="module")
def stops(table) -> np.ndarray:
    """Twenty stops looking down at a part in front of the arm, TCP 0.5-1.1 m high."""
    rng = np.random.default_rng(7)
    out = []
    while len(out) < 20:
        q = rng.uniform([-0.6, -0.3, -0.3, -1.0, 0.6, -1.0], [0.6, 0.5, 0.5, 1.0, 1.4, 1.0])
        if 0.5 < fk_dh(table, q)[2, 3] < 1.1:
            out.append(q)
    return np.array(out)


@pytest.fixture(scope="module")
def candidates(table, T_cell_base, T_tool0_tcp):
    cands, skipped = candidate_views(
        table, SPEC.lower_rad, SPEC.upper_rad, T_cell_base, T_tool0_tcp, TARGETS, STANDOFF_M
    )
    assert not skipped
    return cands


def test_design_beats_the_old_plan(table, T_cell_base, T_tool0_tcp, stops, candidates):
    old = view_plan(
        table, SPEC.lower_rad, SPEC.upper_rad, T_cell_base, T_tool0_tcp, TARGETS, STANDOFF_M
    )
    q_old = np.array([q for _, q in old.poses])
    sigma_old, _ = evaluate(table, T_cell_base, T_tool0_tcp, q_old, stops)
    design = design_views(table, T_cell_base, T_tool0_tcp, candidates, stops)
    assert len(design.views) == len(old.poses) == 6
    assert design.predicted_rms_m < 0.5 * np.sqrt(np.mean(sigma_old**2))
    assert np.all(np.isfinite(design.stop_sigma_m))


def test_designed_views_see_their_target(table, T_cell_base, T_tool0_tcp, stops, candidates):
    design = design_views(table, T_cell_base, T_tool0_tcp, candidates, stops)
    for v in design.views:
        T_cell_tcp = T_cell_base @ fk_dh(table, v.q_rad) @ T_tool0_tcp
        p, n = TARGETS[v.target_id]
        ahead = T_cell_tcp[:3, 3] + STANDOFF_M * T_cell_tcp[:3, 2]
        assert np.allclose(ahead, p, atol=1e-9)
        assert np.isclose(-T_cell_tcp[:3, 2] @ n, np.cos(v.tilt_rad), atol=1e-9)
        lo, hi = np.asarray(SPEC.lower_rad), np.asarray(SPEC.upper_rad)
        assert np.all(v.q_rad >= lo - 1e-9) and np.all(v.q_rad <= hi + 1e-9)


def test_exchange_leaves_no_improving_swap(table, T_tool0_tcp, stops, candidates):
    _, D_v = tcp_sensitivity(table, T_tool0_tcp, np.array([c.q_rad for c in candidates]))
    _, D_s = tcp_sensitivity(table, T_tool0_tcp, stops)
    blocks = np.einsum("vki,vkj->vij", D_v, D_v)
    W = np.einsum("ski,skj->ij", D_s, D_s)
    ridge = np.eye(blocks.shape[1]) * 1e-9
    chosen = choose_by_information(blocks, 6, ridge, W, exchange_passes=50)
    phi = design_value(blocks, chosen, ridge, W)
    for slot in range(6):
        for j in set(range(len(blocks))) - set(chosen):
            swapped = [*chosen[:slot], j, *chosen[slot + 1 :]]
            assert design_value(blocks, swapped, ridge, W) >= phi * (1 - 1e-6)


def test_collision_veto_is_respected(table, T_cell_base, T_tool0_tcp):
    """A veto on every configuration with J1 > 0 leaves target B only back-branch views."""
    cands, _ = candidate_views(
        table, SPEC.lower_rad, SPEC.upper_rad, T_cell_base, T_tool0_tcp, TARGETS, STANDOFF_M,
        accept=lambda q: q[0] <= 0.0,
    )  # fmt: skip
    assert cands and all(c.q_rad[0] <= 0.0 for c in cands)


def test_prediction_matches_simulated_identifications(
    table, T_cell_base, T_tool0_tcp, stops, candidates
):
    """Every link warming along the design's anticipated curve: the error at the stops over
    seeds has the RMS the design predicts (within 35 %)."""
    options = DesignOptions(every_s=600.0)
    design = design_views(table, T_cell_base, T_tool0_tcp, candidates, stops, options)
    warm = WarmUp(options.rise_K, options.tau_s)
    settings = DriftSettings.per_joint(("aluminium",) * 6, (warm,) * 6)
    targets = {k: p for k, (p, _) in TARGETS.items()}
    geometry = CellGeometry(T_cell_base, T_tool0_tcp, targets)
    times = np.arange(0.0, options.duration_s + 1.0, options.every_s)
    truth = DriftTruth(table, settings)
    t_end = np.full(len(stops), options.duration_s)
    sq = []
    for seed in range(12):
        obs = simulate_observations(
            truth.T_base_tool0, truth.sensor_readings, settings.sensor_names, geometry,
            design.poses, times, noise_m=options.noise_m, seed=seed,
        )  # fmt: skip
        spec = ThermalSpec.mapped(obs.sensor_names, reference_from_cold(obs))
        model = identify(obs, geometry, table, spec).model
        readings = truth.sensor_readings(t_end)
        err = (truth.T_base_tool0(stops, t_end) - model.fk(stops, readings))[:, :3, 3]
        sq.append(np.mean(np.sum(err**2, axis=1)))
    actual = float(np.sqrt(np.mean(sq)))
    print(f"actual {actual * 1e6:.2f} um, predicted {design.predicted_rms_m * 1e6:.2f} um")
    assert actual == pytest.approx(design.predicted_rms_m, rel=0.35)


def test_no_stop_or_candidate_is_refused(table, T_cell_base, T_tool0_tcp, candidates):
    from robots.thermal import ThermalDataError

    with pytest.raises(ThermalDataError, match="no tour stops"):
        design_views(table, T_cell_base, T_tool0_tcp, candidates, np.zeros((0, 6)))
    with pytest.raises(ThermalDataError, match="no reachable"):
        design_views(table, T_cell_base, T_tool0_tcp, [], np.zeros((1, 6)))
