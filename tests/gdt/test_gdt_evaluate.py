"""The evaluation on synthetic runs of the built-in frame (:mod:`gdt_fixtures`): the part
placed off its fixture, a datum feature not measured, the bonus, the decisions, and the coverage
of the Monte Carlo U (the measured centres drawn about the truth with the stated covariance)."""

from __future__ import annotations

import numpy as np
import pytest
from gdt_fixtures import placement as _placement
from gdt_fixtures import results as _results
from gdt_fixtures import truth as _truth
from scipy.spatial.transform import Rotation

from cell.config import load_builtin_cell
from cell.gdt.decide import decide_interval, decide_upper, hole_decision
from cell.gdt.evaluate import evaluate
from cell.gdt.montecarlo import McOptions
from cell.gdt.truth_check import coverage, placement_error, true_evaluation

FAST = McOptions(n_draws=600)


@pytest.fixture(scope="module")
def cell():
    return load_builtin_cell()


def test_deviations_in_the_datum_frame_do_not_see_the_placement(cell) -> None:
    cen, dia = _truth(cell, 0)
    on = evaluate(cell, _results(cell, cen, dia, np.eye(4), 0), FAST)
    T = _placement()
    off = evaluate(cell, _results(cell, cen, dia, T, 0), FAST)
    assert len(on.characteristics) == 80 and on.alignment == "DRF1"
    for a, b in zip(on.characteristics, off.characteristics, strict=True):
        assert b["decision"] != "not_evaluated"
        assert b["value_m"] == pytest.approx(a["value_m"], abs=1e-9)
    p = off.placement
    assert p["status"] == "evaluated" and max(p["U_rotation_rad"]) < 2e-4
    truth = true_evaluation(cell, {k: T[:3, :3] @ v + T[:3, 3] for k, v in cen.items()}, dia)
    assert placement_error(p, truth)["within_U"]
    # the true DRF sits where the truth's placement puts it, but for the datum features' own
    # scatter (15 um over the 0.7 m from B to C: some 1e-4 rad)
    rv = Rotation.from_quat(truth.placement["T_fixture_part"]["quat_xyzw"]).as_rotvec()
    assert np.allclose(rv, Rotation.from_matrix(T[:3, :3]).as_rotvec(), atol=1e-4)
    # the fixture frame would have seen millimetres of position error
    fixture = np.linalg.norm(np.subtract(_results(cell, cen, dia, T, 0)[0].center_part_m,
                                         cell.part.holes[0].position))  # fmt: skip
    assert fixture > 1e-3


def test_report_fields_follow_the_schema(cell) -> None:
    cen, dia = _truth(cell, 1)
    ev = evaluate(cell, _results(cell, cen, dia, _placement(), 1), FAST).fields()
    drf = ev["datum_reference_frames"][0]
    assert drf["id"] == "DRF1" and drf["datums"] == ["A", "B", "C"]
    assert set(drf["U_T_part_drf"]) == {"xyz_m", "rotation_rad"} and drf["status"] == "evaluated"
    assert set(drf["residuals_m"]) == {"A", "B", "C"} and 0 < drf["residuals_m"]["A"] < 3e-5
    assert [d["label"] for d in ev["datums"]] == ["A", "B", "C"]
    pos = next(c for c in ev["characteristics"] if c["id"] == "EML1.position")
    assert pos["kind"] == "position" and pos["material_condition"] == "MMC"
    assert pos["value_m"] == pytest.approx(2 * np.hypot(*pos["deviation_m"][:2]), rel=1e-3) or (
        pos["value_m"] <= 2 * np.linalg.norm(pos["deviation_m"]) + 1e-12
    )
    assert pos["bonus_m"] > 0 and pos["U_m"] > 0 and len(pos["actual_m"]) == 3
    size = next(c for c in ev["characteristics"] if c["id"] == "EML1.diameter")
    assert size["kind"] == "diameter" and size["upper_m"] > size["lower_m"] == 0.0
    assert size["deviation_m"] == pytest.approx(size["actual_m"] - size["nominal_m"])


def test_unmeasured_datum_feature_leaves_its_characteristics_not_evaluated(cell) -> None:
    cen, dia = _truth(cell, 2)
    ev = evaluate(cell, _results(cell, cen, dia, np.eye(4), 2, missing=("PVL",)), FAST)
    assert ev.datum_reference_frames[0]["status"] == "not_evaluated"
    assert "datum B" in ev.datum_reference_frames[0]["reason"]
    assert ev.placement["status"] == "not_evaluated"
    pos = [c for c in ev.characteristics if c["kind"] == "position"]
    assert pos and all(c["decision"] == "not_evaluated" and "PVL" in c["reason"] for c in pos)
    sizes = [c for c in ev.characteristics if c["kind"] == "diameter" and c["hole_id"] != "PVL"]
    assert all(c["decision"] != "not_evaluated" for c in sizes)
    assert next(d for d in ev.datums if d["label"] == "A")["measured"] is False


def test_a_hole_out_of_its_zone_is_proven_nonconforming(cell) -> None:
    cen, dia = _truth(cell, 3)
    cen["EML2"] = cen["EML2"] + [4e-4, 0.0, 0.0]  # 0.4 mm in its plane: value 0.8 mm
    dia["EML3"] = cell.part.holes[13].diameter - 30e-6  # 30 um under its H9 limit
    ev = evaluate(cell, _results(cell, cen, dia, _placement(), 3), FAST)
    by_id = {c["id"]: c for c in ev.characteristics}
    assert by_id["EML2.position"]["decision"] == "nonconformance"
    assert by_id["EML2.position"]["value_m"] == pytest.approx(8e-4, abs=1e-4)
    assert by_id["EML3.diameter"]["decision"] == "nonconformance"
    assert by_id["EML3.position"]["bonus_m"] == 0.0  # under MMC: no bonus
    assert sum(c["decision"] == "conformance" for c in ev.characteristics) >= 70


def test_monte_carlo_U_covers_the_truth(cell) -> None:
    covered = []
    for seed in range(10):
        cen, dia = _truth(cell, 10 + seed)
        ev = evaluate(cell, _results(cell, cen, dia, _placement(), 10 + seed),
                      McOptions(n_draws=1000))  # fmt: skip
        cov = coverage(ev.characteristics, true_evaluation(cell, cen, dia))
        covered += cov.of_kind("position")
    assert 0.9 <= np.mean(covered) <= 0.99, np.mean(covered)


def test_decision_rules() -> None:
    assert decide_upper(1e-4, 5e-5, 3e-4, "iso14253") == "conformance"
    assert decide_upper(2.8e-4, 5e-5, 3e-4, "iso14253") == "inconclusive"
    assert decide_upper(2.8e-4, 5e-5, 3e-4, "simple") == "conformance"
    assert decide_upper(4e-4, 5e-5, 3e-4, "iso14253") == "nonconformance"
    assert decide_interval(1e-5, 4e-6, 0.0, 2.2e-5, "iso14253") == "conformance"
    assert decide_interval(2e-6, 4e-6, 0.0, 2.2e-5, "iso14253") == "inconclusive"
    assert decide_interval(-5e-6, 4e-6, 0.0, 2.2e-5, "iso14253") == "nonconformance"
    assert hole_decision(["conformance", "not_evaluated"]) is None
    assert hole_decision(["nonconformance", "not_evaluated"]) == "nonconforming"
    assert hole_decision(["conformance", "inconclusive"]) == "inconclusive"
