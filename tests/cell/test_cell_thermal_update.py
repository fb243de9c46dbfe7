"""The run's thermal update: observation rows, refusal when nothing is identifiable, and the
check of a given model against the reference targets."""

from __future__ import annotations

import numpy as np
from cell_fixtures import SmallCell

from cell.run.thermal_update import ThermalUpdate, sensor_spec
from robots.thermal.compensate import compensated_T_cell_tcp
from robots.thermal.model import ThermalModel
from robots.transforms import invert


def _rows(sc: SmallCell, tu: ThermalUpdate, offset_m: float) -> None:
    arm = tu.arm
    targets = {r.id: np.asarray(r.position, float) for r in sc.cell.reference_targets}
    for s in sc.reference.stops:
        target = s.hole_id.split("#")[0]
        T_tcp_cell = invert(arm.fk(np.array(s.q), "tcp"))
        p = T_tcp_cell[:3, :3] @ targets[target] + T_tcp_cell[:3, 3]
        tu.add(0.0, target, np.array(s.q), np.full(6, 20.0), p + np.array([offset_m, 0.0, 0.0]))


def test_one_moment_is_not_identifiable(small_cell: SmallCell) -> None:
    tu = ThermalUpdate(small_cell.cell, small_cell.cell.build_arm())
    assert tu.identify() is None and tu.refusal == "no reference observations"
    _rows(small_cell, tu, 0.0)
    assert tu.identify() is None and "single temperature state (1 round" in tu.refusal


def test_check_of_a_given_model(small_cell: SmallCell) -> None:
    arm = small_cell.cell.build_arm()
    model = ThermalModel(arm.dh, sensor_spec(6, 20.0), {}, T_cell_base=arm.T_cell_base,
                         T_tool0_tcp=arm.T_tool0_tcp)  # fmt: skip
    exact, shifted = ThermalUpdate(small_cell.cell, arm), ThermalUpdate(small_cell.cell, arm)
    _rows(small_cell, exact, 0.0)
    _rows(small_cell, shifted, 30e-6)
    assert exact.check(model) < 1e-9
    assert abs(shifted.check(model) - 30e-6) < 1e-9


def test_reference_temperatures_are_the_first_rounds_readings(small_cell: SmallCell) -> None:
    """Rows from an arm whose nominal table holds at 24 degC, seen in a cold round (24 degC) and a
    warm one (34 degC): the identified model's reference is the cold readings, not 20 degC, and
    it predicts the warm round."""
    arm = small_cell.cell.build_arm()
    truth = ThermalModel(arm.dh, sensor_spec(6, 24.0), {"k_link2": 3e-5, "k_link3": 2e-5},
                         T_cell_base=arm.T_cell_base, T_tool0_tcp=arm.T_tool0_tcp)  # fmt: skip
    targets = {r.id: np.asarray(r.position, float) for r in small_cell.cell.reference_targets}
    tu = ThermalUpdate(small_cell.cell, arm)
    for rnd, temp in enumerate((24.0, 34.0)):
        for s in small_cell.reference.stops:
            target, q, temps = s.hole_id.split("#")[0], np.array(s.q), np.full(6, temp)
            T_tcp_cell = invert(
                compensated_T_cell_tcp(truth, arm.T_cell_base, arm.T_tool0_tcp, q, temps)
            )
            p = T_tcp_cell[:3, :3] @ targets[target] + T_tcp_cell[:3, 3]
            tu.add(100.0 * rnd, target, q, temps, p, rnd)
    assert tu.reference_degC() == (24.0,) * 6
    model = tu.identify()
    assert model is not None, tu.refusal
    assert model.spec.reference_degC == (24.0,) * 6
    assert tu.check(model) < 1e-7
