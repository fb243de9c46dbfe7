"""The temperature readings' noise: estimated by the identification, propagated to a stop."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from robots.thermal import (
    DriftTruth,
    ThermalSpec,
    default_settings,
    identify,
    reference_from_cold,
    simulate_observations,
)
from robots.thermal.identify import reading_noise_K
from robots.thermal.uncertainty import reading_covariance

TIMES = np.arange(0.0, 7201.0, 600.0)
Q_STOP = np.array([0.1, 0.4, -0.3, 0.3, 0.9, 0.2])


def test_reading_noise_is_recovered_from_a_warm_up(table):
    """A first-order warm-up read with 0.05 K noise: the quartic's residual gives 0.05 K."""
    truth = DriftTruth(table, default_settings(per_joint_noise_K=0.05), seed=4)
    t = np.sort(np.random.default_rng(5).uniform(0.0, 5400.0, 60))
    est = reading_noise_K(t, truth.sensor_readings(t))
    assert 0.04 < est < 0.065
    assert reading_noise_K(t[:10], truth.sensor_readings(t[:10])) == 0.0  # too few rows


def test_identification_keeps_the_reading_noise(table, cell):
    truth = DriftTruth(table, default_settings(per_joint_noise_K=0.05))
    geometry, plan = cell
    obs = simulate_observations(truth.T_base_tool0, truth.sensor_readings,
                                truth.settings.sensor_names, geometry, plan, TIMES,
                                noise_m=5e-6, seed=2)  # fmt: skip
    spec = ThermalSpec.mapped(obs.sensor_names, reference_from_cold(obs))
    model = identify(obs, geometry, table, spec).model
    assert 0.03 < model.fit["reading_noise_K"] < 0.08


def test_reading_covariance_matches_sampled_readings(table, cell):
    """2 u^2 H H^T against compensated positions with the stop's and the reference's readings
    drawn with noise u (the model is linear in the readings: agreement within sampling)."""
    truth = DriftTruth(table, default_settings(per_joint_noise_K=0.0))
    geometry, plan = cell
    obs = simulate_observations(truth.T_base_tool0, truth.sensor_readings,
                                truth.settings.sensor_names, geometry, plan, TIMES,
                                noise_m=5e-6, seed=3)  # fmt: skip
    ref = np.array(reference_from_cold(obs))
    model = identify(obs, geometry, table, ThermalSpec.mapped(obs.sensor_names, tuple(ref))).model
    temps = ref + 12.0
    p = np.array([0.0, 0.0, 0.25])
    u = 0.2
    C = reading_covariance(model, Q_STOP, temps, p, u_reading_K=u)
    rng = np.random.default_rng(0)
    pts = []
    for _ in range(2000):
        spec = replace(model.spec, reference_degC=tuple(ref + rng.normal(0.0, u, 6)))
        m = replace(model, spec=spec)
        T = m.T_cell_base @ m.fk(Q_STOP, temps + rng.normal(0.0, u, 6)) @ m.T_tool0_tcp
        pts.append((T @ np.append(p, 1.0))[:3])
    S = np.cov(np.array(pts).T)
    assert np.trace(C) > 0
    assert abs(np.trace(S) / np.trace(C) - 1.0) < 0.12
    assert np.allclose(reading_covariance(replace(model, fit={}), Q_STOP, temps, p), 0.0)
