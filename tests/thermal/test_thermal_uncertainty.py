"""The prediction covariance at a pose: propagation, file round trip, honesty against seeds."""

from __future__ import annotations

import json
from dataclasses import replace

import numpy as np
import pytest

from robots.thermal import (
    DriftTruth,
    ThermalModelFileError,
    ThermalSpec,
    default_settings,
    identify,
    reference_from_cold,
    simulate_observations,
)
from robots.thermal.modelfile import load_model, model_to_dict, save_model
from robots.thermal.uncertainty import covariance_matrix, term_jacobian

TIMES = np.arange(0.0, 7201.0, 600.0)
Q_EVAL = np.array([[0.1, 0.4, -0.3, 0.3, 0.9, 0.2], [-0.5, 0.2, 0.1, -0.8, 1.1, 0.0]])


def _model(table, cell, seed):
    truth = DriftTruth(table, default_settings(per_joint_noise_K=0.0))
    geometry, plan = cell
    obs = simulate_observations(
        truth.T_base_tool0,
        truth.sensor_readings,
        truth.settings.sensor_names,
        geometry,
        plan,
        TIMES,
        noise_m=5e-6,
        seed=seed,
    )
    spec = ThermalSpec.mapped(obs.sensor_names, reference_from_cold(obs))
    return identify(obs, geometry, table, spec).model, truth


@pytest.fixture(scope="module")
def model_truth(table, cell):
    return _model(table, cell, seed=3)


def test_covariance_is_stored_and_matches_std(model_truth):
    model, _ = model_truth
    S = covariance_matrix(model)
    assert S.shape == (len(model.coefficients),) * 2
    assert np.allclose(np.sqrt(np.diag(S)), [model.std[n] for n in model.coefficients])
    assert np.allclose(S, S.T)


def test_jacobian_is_linear_in_the_length_terms(model_truth):
    """p(theta + e_j) - p(theta) equals the column of the Jacobian (lengths enter linearly)."""
    model, _ = model_truth
    temps = np.full(6, 35.0)
    G = term_jacobian(model, Q_EVAL[0], temps, point_tcp_m=[0.0, 0.0, 0.25])
    name = "k_link2"
    j = list(model.coefficients).index(name)
    bumped = replace(
        model, coefficients={**model.coefficients, name: model.coefficients[name] + 1e-5}
    )
    p = np.array([0.0, 0.0, 0.25, 1.0])
    diff = (bumped.fk(Q_EVAL[0], temps) @ model.T_tool0_tcp @ p)[:3] - (
        model.fk(Q_EVAL[0], temps) @ model.T_tool0_tcp @ p
    )[:3]
    assert np.allclose(diff, G[:, j] * 1e-5, atol=1e-12)


def test_covariance_grows_with_the_rise_and_vanishes_cold(model_truth):
    model, _ = model_truth
    ref = np.asarray(model.spec.reference_degC)
    C0 = model.predict_covariance(Q_EVAL, np.broadcast_to(ref, (2, 6)))
    C5 = model.predict_covariance(Q_EVAL, np.broadcast_to(ref + 5.0, (2, 6)))
    C10 = model.predict_covariance(Q_EVAL, np.broadcast_to(ref + 10.0, (2, 6)))
    assert C10.shape == (2, 3, 3)
    assert np.allclose(C0, 0.0)
    assert np.allclose(C10, 4.0 * C5, rtol=1e-6)  # linear in the rise: quadratic covariance
    assert np.all(np.linalg.eigvalsh(C10) > -1e-18)


def test_predicted_error_is_honest_over_seeds(table, cell):
    """Over noise seeds the squared error at a pose averages to the predicted variance
    (the matched truth: the model's structure is right)."""
    ratios = []
    for seed in range(8):
        model, truth = _model(table, cell, seed)
        t = np.full(len(Q_EVAL), 7200.0)
        temps = truth.sensor_readings(t, noisy=False)
        err = (truth.T_base_tool0(Q_EVAL, t) - model.fk(Q_EVAL, temps))[:, :3, 3]
        C = model.predict_covariance(Q_EVAL, temps, T_cell_base=np.eye(4))
        ratios.append(np.sum(err**2) / np.trace(C, axis1=-2, axis2=-1).sum())
    assert 0.3 < np.mean(ratios) < 3.0


def test_thermal_json_round_trip_keeps_the_covariance(tmp_path, model_truth):
    model, _ = model_truth
    path = tmp_path / "thermal.json"
    save_model(path, model)
    back = load_model(path)
    assert np.allclose(back.covariance, model.covariance)
    q, temps = Q_EVAL[0], np.full(6, 30.0)
    assert np.allclose(back.predict_covariance(q, temps), model.predict_covariance(q, temps))


def test_thermal_json_without_covariance_uses_std(tmp_path, model_truth):
    model, _ = model_truth
    doc = model_to_dict(model)
    del doc["covariance"]
    path = tmp_path / "old.json"
    path.write_text(json.dumps(doc))
    S = covariance_matrix(load_model(path))
    assert np.allclose(np.diag(S), [model.std[n] ** 2 for n in model.coefficients])


@pytest.mark.parametrize(
    ("edit", "field"),
    [
        (lambda c: c.update(terms=c["terms"][:-1]), "covariance.terms"),
        (lambda c: c["matrix"][0].__setitem__(1, c["matrix"][0][1] + 1.0), "covariance.matrix"),
        (lambda c: c["matrix"].__setitem__(0, ["x"] * len(c["terms"])), "covariance.matrix[0]"),
    ],
)
def test_bad_covariance_is_refused_naming_the_field(tmp_path, model_truth, edit, field):
    model, _ = model_truth
    doc = model_to_dict(model)
    edit(doc["covariance"])
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(doc))
    with pytest.raises(ThermalModelFileError, match=field.replace("[", r"\[").replace("]", r"\]")):
        load_model(path)
