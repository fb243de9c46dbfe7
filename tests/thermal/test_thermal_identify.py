"""Identification: exact recovery, uncertainty, the rank report and refusals."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from robots.dh import fk_dh
from robots.thermal import (
    CellGeometry,
    DriftTruth,
    IdentifyOptions,
    ThermalDataError,
    ThermalSpec,
    ThermalSpecError,
    UnidentifiableError,
    default_settings,
    identify,
    reference_from_cold,
    simulate_observations,
)
from robots.thermal.drift import DriftSettings, WarmUp
from robots.transforms import pose_to_matrix

TIMES = np.arange(0.0, 7201.0, 600.0)


def _observe(truth, cell, noise_m=0.0, times=TIMES, seed=0):
    geometry, plan = cell
    return simulate_observations(
        truth.T_base_tool0,
        lambda t: truth.sensor_readings(t, noisy=noise_m > 0),
        truth.settings.sensor_names,
        geometry,
        plan,
        times,
        noise_m=noise_m,
        seed=seed,
    )


def test_exact_recovery_of_length_coefficients_from_noise_free_data(table, cell):
    truth = DriftTruth(table, default_settings(per_joint_noise_K=0.0))
    obs = _observe(truth, cell)
    spec = ThermalSpec.mapped(obs.sensor_names, reference_from_cold(obs))
    res = identify(obs, cell[0], table, spec)
    assert res.status == "partial"
    assert set(res.report.refused) == {"k_link5"}
    assert "no D-H length" in res.report.refused["k_link5"]
    for i in (0, 1, 2, 3, 5):
        assert res.model.coefficients[f"k_link{i + 1}"] == pytest.approx(
            truth.expansion_per_K[i], abs=1e-11
        )
    assert res.residual_rms_m < 1e-12
    assert res.residual_rms_before_m > 1e-5


def test_exact_recovery_with_joint_offset_drift(table, cell):
    base = default_settings(per_joint_noise_K=0.0)
    c_true = (2e-6, -3e-6, 1.5e-6, 0.0, 4e-6, 0.0)
    truth = DriftTruth(table, dataclasses.replace(base, offset_drift_rad_per_K=c_true))
    obs = _observe(truth, cell)
    spec = ThermalSpec.mapped(obs.sensor_names, reference_from_cold(obs), offsets=True)
    res = identify(obs, cell[0], table, spec)
    for i in range(6):
        name = f"c_joint{i + 1}"
        if name in res.model.coefficients:
            assert res.model.coefficients[name] == pytest.approx(c_true[i], abs=1e-11)
    assert {"c_joint1", "c_joint2", "c_joint3", "c_joint5"} <= set(res.model.coefficients)
    assert res.model.coefficients["k_link2"] == pytest.approx(23e-6, abs=1e-11)


def test_uncertainty_covers_the_error_under_noise(table, cell):
    truth = DriftTruth(table, default_settings(per_joint_noise_K=0.0))
    obs = _observe(truth, cell, noise_m=5e-6, times=np.arange(0.0, 7201.0, 300.0), seed=7)
    spec = ThermalSpec.mapped(obs.sensor_names, reference_from_cold(obs))
    res = identify(obs, cell[0], table, spec)
    assert res.sigma_m == pytest.approx(5e-6, rel=0.15)
    for name, value in res.model.coefficients.items():
        i = int(name[-1]) - 1
        assert abs(value - truth.expansion_per_K[i]) < 4.5 * res.model.std[name]
    assert res.model.std["k_link2"] < 2e-6


def test_wrist_only_plan_cannot_separate_the_arm_links(table, make_cell):
    """Poses that share J1..J3 see every arm length along three fixed directions."""
    qs = [
        (0.3, 0.4, -0.3, w4, w5, w6) for w4, w5, w6 in [(0, 0.8, 0), (1, 1.1, 0.5), (-1, 0.6, -1)]
    ]
    cell = make_cell(qs)
    s = default_settings(per_joint_noise_K=0.0)
    single = DriftSettings(s.materials, s.link_warmup, ("ambient",), (WarmUp(15.0, 2400.0),))
    truth = DriftTruth(table, single)
    obs = _observe(truth, cell)
    spec = ThermalSpec.mapped(("ambient",), reference_from_cold(obs))
    res = identify(obs, cell[0], table, spec)
    assert res.report.condition_all > 1e6
    assert res.report.rank < 5
    not_separable = [n for n, r in res.report.refused.items() if "not separable" in r]
    assert len(not_separable) >= 2
    assert res.report.condition_kept <= 1e3
    assert set(res.report.kept) | set(res.report.refused) == set(spec.candidate_terms())


def test_constant_sensor_and_single_time_are_refused(table, cell):
    s = default_settings(per_joint_noise_K=0.0)
    frozen = DriftSettings(s.materials, s.link_warmup, ("ambient",), (WarmUp(0.0, 100.0),))
    truth = DriftTruth(table, frozen)
    obs = _observe(truth, cell)
    spec = ThermalSpec.mapped(("ambient",), reference_from_cold(obs))
    with pytest.raises(UnidentifiableError, match="never changes") as info:
        identify(obs, cell[0], table, spec)
    assert "k_link2" in info.value.refused
    warm = DriftTruth(table, default_settings(per_joint_noise_K=0.0))
    once = _observe(warm, cell, times=np.array([600.0]))
    with pytest.raises(UnidentifiableError):
        identify(once, cell[0], table, ThermalSpec.mapped(once.sensor_names, (20.0,) * 6))


def test_joint6_offset_is_invisible_with_the_target_on_the_j6_axis(table):
    """A TCP on the flange axis and targets at the TCP: a J6 offset drift moves nothing measured."""
    T_tool0_tcp = pose_to_matrix([0.0, 0.0, 0.3])
    qs = [
        (0.0, 0.3, -0.2, 0.5, 0.8, 0.1),
        (0.6, 0.1, 0.2, -0.5, 1.0, 0.3),
        (-0.7, 0.5, -0.4, 0.2, -0.9, -0.2),
    ]
    plan = [(f"T{i}", np.asarray(q)) for i, q in enumerate(qs)]
    targets = {tid: (fk_dh(table, q) @ T_tool0_tcp)[:3, 3] for tid, q in plan}
    geometry = CellGeometry(np.eye(4), T_tool0_tcp, targets)
    truth = DriftTruth(table, default_settings(per_joint_noise_K=0.0))
    obs = _observe(truth, (geometry, plan))
    spec = ThermalSpec.mapped(obs.sensor_names, reference_from_cold(obs), offsets=True)
    res = identify(obs, geometry, table, spec)
    assert "no measurable effect" in res.report.refused["c_joint6"]
    assert "c_joint5" in res.report.kept


def test_sensor_names_must_match_the_spec(table, cell):
    truth = DriftTruth(table, default_settings(per_joint_noise_K=0.0))
    obs = _observe(truth, cell)
    spec = ThermalSpec.mapped(("amb",), (20.0,))
    with pytest.raises(ThermalDataError, match="the model expects"):
        identify(obs, cell[0], table, spec)


def test_options_are_checked():
    with pytest.raises(ThermalSpecError, match="max_condition"):
        IdentifyOptions(max_condition=0.5)
