"""The drift generator: warm-up curves, materials, sensors, true kinematics."""

from __future__ import annotations

import numpy as np
import pytest

from robots.dh import fk_dh
from robots.thermal import DriftSettings, DriftTruth, ThermalSpecError, WarmUp, default_settings


def test_warm_up_curve_is_first_order():
    w = WarmUp(15.0, 1800.0)
    assert w.rise_at(0.0) == 0.0
    assert w.rise_at(1800.0) == pytest.approx(15.0 * (1 - np.exp(-1)))
    assert w.rise_at(1e7) == pytest.approx(15.0)
    assert w.rise_at(-5.0) == 0.0
    with pytest.raises(ThermalSpecError):
        WarmUp(1.0, 0.0)


def test_truth_is_nominal_when_cold_and_grows_by_material(table):
    truth = DriftTruth(table, default_settings(per_joint_noise_K=0.0))
    q = np.array([0.0, 0.0, 0.0, 0.0, 0.0, 0.0])
    assert np.allclose(truth.T_base_tool0(q, 0.0), fk_dh(table, q), atol=1e-15)
    assert truth.expansion_per_K.tolist() == [10e-6, 23e-6, 12e-6, 23e-6, 12e-6, 12e-6]
    hot = truth.table_at(1e7)  # fully warm: link 2 (aluminium) +15 K
    assert hot.a_m[1] == pytest.approx(0.7 * (1 + 23e-6 * 15.0))
    assert hot.d_m[0] == pytest.approx(0.445 * (1 + 10e-6 * 8.0))
    # at q = 0 the arm points along base x: the flange moves by roughly a few tenths of a mm
    drift = truth.T_base_tool0(q, 1e7)[:3, 3] - fk_dh(table, q)[:3, 3]
    assert 1e-4 < np.linalg.norm(drift) < 1e-3


def test_sensors_match_links_and_mismatch_when_told(table):
    s = default_settings(per_joint_noise_K=0.0)
    truth = DriftTruth(table, s)
    t = np.array([0.0, 600.0, 3600.0])
    assert np.allclose(truth.sensor_readings(t), truth.link_temperatures(t))
    lagging = DriftSettings(
        materials=s.materials,
        link_warmup=s.link_warmup,
        sensor_names=("ambient",),
        sensor_warmup=(WarmUp(3.0, 900.0),),
    )
    readings = DriftTruth(table, lagging).sensor_readings(t)
    assert readings.shape == (3, 1)
    assert readings[2, 0] < truth.link_temperatures(3600.0)[1]


def test_sensor_noise_is_applied(table):
    truth = DriftTruth(table, default_settings(per_joint_noise_K=0.1), seed=3)
    r = truth.sensor_readings(np.zeros(2000)) - 20.0
    assert 0.08 < r.std() < 0.12


def test_bad_settings_are_refused():
    with pytest.raises(ThermalSpecError, match="known materials"):
        DriftSettings.per_joint(("wood",) * 6, (WarmUp(1.0, 1.0),) * 6)
