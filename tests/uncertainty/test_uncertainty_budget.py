"""The uncertainty budget's pieces against independent references: the calibration Jacobian
against a Monte Carlo with the measurement's own fit, the ISO 9283 conversion against simulated
scatter, the second-order distance term against sampling, the decision rule, the ISO 1
correction, and refusals of bad part temperatures and materials naming the field."""

from __future__ import annotations

import numpy as np
import pytest
import yaml

from cell.config import builtin_cell_path, parse_cell
from cell.errors import ConfigError
from cell.uncertainty.budget import Contribution, combine
from cell.uncertainty.calibration import (
    default_uncertainty,
    jacobian_covariance,
    monte_carlo_covariance,
)
from cell.uncertainty.decision import decide_hole, decide_one
from cell.uncertainty.errors import PartTemperatureError
from cell.uncertainty.materials import Material
from cell.uncertainty.part_temperature import PartThermalState, part_state
from cell.uncertainty.repeatability import RP_PER_SIGMA, repeatability_rp_m, sigma_per_axis_m
from measure import measure_hole
from measure.synth import render_hole_pair, standard_stereo


def test_calibration_jacobian_agrees_with_monte_carlo() -> None:
    st = standard_stereo()
    n = np.array([0.2, 0.0, -1.0]) / np.linalg.norm([0.2, 0.0, -1.0])
    pair = render_hole_pair(st, [0.05, 0.0, 0.245], n, 0.010, seed=3)
    m = measure_hole(pair.left, pair.right, st, expected_diameter_m=0.010)
    pts = m.points_m[m.inliers]
    unc = default_uncertainty(st)
    J = np.sqrt(np.diag(jacobian_covariance(st, pts, unc)))
    M = np.sqrt(np.diag(monte_carlo_covariance(st, pts, unc, n=80, seed=1)))
    assert np.all(J > 0)
    # 80 draws: the standard deviation is known to about 8 %
    np.testing.assert_allclose(J, M, rtol=0.25)


def test_iso9283_rp_matches_simulated_scatter() -> None:
    """RP = mean + 3 std of the distances from the barycentre, over simulated approaches."""
    rng = np.random.default_rng(0)
    s = 10e-6
    p = rng.normal(0.0, s, (200_000, 3))
    lengths = np.linalg.norm(p - p.mean(axis=0), axis=1)
    rp = lengths.mean() + 3 * lengths.std()
    assert rp / s == pytest.approx(RP_PER_SIGMA, rel=0.01)
    assert sigma_per_axis_m(rp) == pytest.approx(s, rel=0.01)
    assert repeatability_rp_m("abb_irb2600_20_165", None)[0] == pytest.approx(0.04e-3)
    assert repeatability_rp_m("abb_irb2600_20_165", 0.03e-3)[0] == pytest.approx(0.03e-3)


@pytest.mark.parametrize("d_true_um", [0.0, 5.0, 20.0, 60.0])
def test_position_uncertainty_covers_sampled_distances(d_true_um: float) -> None:
    """The in-plane distance's u (first + second order, bounded) against sampling: k = 2
    covers 90-99 % of |d - d_true| wherever the true deviation lies."""
    rng = np.random.default_rng(1)
    n = np.array([0.0, 0.0, 1.0])
    s = 10e-6
    S = np.diag([s * s, (0.7 * s) ** 2, (3 * s) ** 2])
    true = np.array([d_true_um * 1e-6, 0.0, 0.0])
    e = rng.multivariate_normal(np.zeros(3), S, 4000)
    covered = []
    for ei in e[:1500]:
        meas = true + ei
        b = combine([Contribution("x", S, 0.0)], meas, n)
        d = np.linalg.norm(meas[:2])
        covered.append(abs(d - d_true_um * 1e-6) <= b.U_position_m)
    assert 0.90 <= np.mean(covered) <= 0.995


def test_decision_rule() -> None:
    t = 50e-6
    assert decide_one(20e-6, 25e-6, t, "iso14253") == "conforming"
    assert decide_one(30e-6, 25e-6, t, "iso14253") == "inconclusive"
    assert decide_one(-80e-6, 25e-6, t, "iso14253") == "nonconforming"
    assert decide_one(30e-6, 25e-6, t, "simple") == "conforming"
    assert decide_one(60e-6, 25e-6, t, "simple") == "nonconforming"
    assert decide_hole(["conforming", "inconclusive"]) == "inconclusive"
    assert decide_hole(["inconclusive", "nonconforming"]) == "nonconforming"
    assert decide_hole(["conforming", "conforming"]) == "conforming"


def test_iso1_correction_and_its_uncertainty() -> None:
    steel = Material("steel", 11.5e-6, 1e-6)
    st = PartThermalState(25.0, 0.5, steel, "measured")
    p = np.array([1.3, 0.0, 0.0])
    assert np.linalg.norm(p - st.to_20c(p)) == pytest.approx(1.3 * 11.5e-6 * 5, rel=1e-3)
    assert st.relative_u() == pytest.approx(np.hypot(11.5e-6 * 0.5, 5 * 1e-6))


def _cell_with(**part) -> str:
    data = yaml.safe_load(builtin_cell_path().read_text())
    data["part"].update(part)
    return yaml.safe_dump(data, sort_keys=False)


@pytest.mark.parametrize(
    ("part", "field"),
    [({"material": "unobtainium"}, "part.material"),
     ({"material": {"name": "x", "alpha_per_K": 11.5, "u_alpha_per_K": 1e-6}},
      "part.material.alpha_per_K"),
     ({"material": {"name": "x", "alpha_per_K": 11.5e-6}}, "part.material.u_alpha_per_K"),
     ({"temperature_c": 293.15}, "part.temperature_c"),
     ({"temperature_c": "warm"}, "part.temperature_c"),
     ({"u_temperature_K": 0.5}, "part.u_temperature_K"),
     ({"temperature_c": 21.0, "u_temperature_K": -1}, "part.u_temperature_K")],
)  # fmt: skip
def test_bad_part_temperature_or_material_names_the_field(part: dict, field: str) -> None:
    with pytest.raises(ConfigError) as err:
        parse_cell(_cell_with(**part), "cell.yaml")
    assert f"cell.yaml: {field}:" in str(err.value)


def test_part_state_sources() -> None:
    cell = parse_cell(_cell_with(material="aluminium", temperature_c=22.5), "c.yaml")
    assert part_state(cell).source == "cell file"
    assert part_state(cell).material.alpha_per_K == pytest.approx(23e-6)
    assert part_state(cell, 24.0, 0.1).temperature_c == 24.0
    with pytest.raises(PartTemperatureError, match="--part-temperature"):
        part_state(cell, 297.15)
    plain = parse_cell(builtin_cell_path().read_text(), "c.yaml")
    assert part_state(plain).source == "assumed" and part_state(plain).temperature_c == 20.0
