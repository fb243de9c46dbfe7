"""The thermal model: batched forward kinematics, drifted tables, the sensor map."""

from __future__ import annotations

import numpy as np
import pytest

from robots.dh import fk_dh
from robots.thermal import ThermalModel, ThermalSpec, ThermalSpecError
from robots.thermal.model import drifted_arrays, fk_rows, term_kind_and_link


def test_fk_rows_matches_fk_dh_for_the_nominal_table(table):
    q = np.random.default_rng(0).uniform(-2, 2, (20, 6))
    a, d, alpha, theta = drifted_arrays(table, np.zeros(6), np.zeros(6), np.zeros((20, 6)))
    assert np.allclose(fk_rows(a, d, alpha, theta, q), fk_dh(table, q), atol=1e-15)


def test_drifted_lengths_scale_linearly_per_link(table):
    k = np.array([10e-6, 23e-6, 12e-6, 23e-6, 0.0, 12e-6])
    dT = np.array([1.0, 2.0, 3.0, 4.0, 5.0, 6.0])
    a, d, _, theta = drifted_arrays(table, k, np.zeros(6), dT)
    a0, d0, _, th0 = table.arrays()
    assert np.allclose(a, a0 * (1 + k * dT))
    assert np.allclose(d, d0 * (1 + k * dT))
    assert np.array_equal(theta, th0)
    # 15 K of aluminium on a2 = 0.7 m: 0.2415 mm
    a15, _, _, _ = drifted_arrays(table, k, np.zeros(6), np.full(6, 15.0))
    assert a15[1] - a0[1] == pytest.approx(0.7 * 23e-6 * 15, rel=1e-9)


def test_model_fk_uses_the_sensor_map_and_reference(table):
    spec = ThermalSpec(("amb",), (0,) * 6, (21.0,))
    model = ThermalModel(table, spec, {"k_link2": 20e-6, "c_joint1": 1e-6})
    q = np.array([0.1, 0.2, 0.3, 0.4, 0.5, 0.6])
    assert np.allclose(model.fk(q, [21.0]), fk_dh(table, q), atol=1e-15)
    warm = model.table_at([31.0])
    assert warm.a_m[1] == pytest.approx(0.7 * (1 + 20e-6 * 10))
    assert warm.theta_offset_rad[0] == pytest.approx(10e-6)
    assert np.allclose(model.fk(q, [31.0]), fk_dh(warm, q), atol=1e-15)


def test_spec_mapping_rules():
    six = tuple(f"j{i}" for i in range(1, 7))
    assert ThermalSpec.mapped(six, (20.0,) * 6).sensor_of_link == (0, 1, 2, 3, 4, 5)
    assert ThermalSpec.mapped(("amb",), (20.0,)).sensor_of_link == (0,) * 6
    with pytest.raises(ThermalSpecError, match="say which sensor drives"):
        ThermalSpec.mapped(("a", "b"), (20.0, 20.0))
    spec = ThermalSpec.mapped(("a", "b"), (20.0, 21.0), ("a", "a", "b", "b", "b", "b"))
    assert spec.link_delta_K(np.array([22.0, 25.0])).tolist() == [2, 2, 4, 4, 4, 4]
    with pytest.raises(ThermalSpecError, match="not among the sensors"):
        ThermalSpec.mapped(("a", "b"), (20.0, 20.0), ("a", "a", "c", "b", "b", "b"))
    with pytest.raises(ThermalSpecError, match="one value per sensor"):
        ThermalSpec(("a",), (0,) * 6, (20.0, 1.0))
    with pytest.raises(ThermalSpecError, match="expected 1 sensor readings"):
        ThermalSpec(("a",), (0,) * 6, (20.0,)).link_delta_K([1.0, 2.0])


def test_term_names():
    assert term_kind_and_link("k_link3") == ("k", 2)
    assert term_kind_and_link("c_joint6") == ("c", 5)
    with pytest.raises(ThermalSpecError, match="unknown term"):
        term_kind_and_link("k_link7")
