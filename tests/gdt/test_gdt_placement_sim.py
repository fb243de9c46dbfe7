"""End to end on the simulator (slow: two whole demos): the built-in frame placed off its
fixture by 1.5 mm and 0.4 deg (the simulated truth's ``part_placement_error``) gives the same
characteristics in the datum frame as on its fixture, within their U, and the reported
placement equals the true one within its U. (A faster synthetic version is in
``test_gdt_evaluate.py``; ``benchmarks/gdt_placement.py`` runs more seeds.)"""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from gdt_fixtures import placement

from cell.config import load_builtin_cell
from cell.demo.demo import DemoOptions, demo_truth, demo_world, run_demo
from cell.gdt.truth_check import placement_error, true_evaluation
from cell.sim.world import SimWorld
from robots.transforms import invert


def _demo(out: Path, T_err: np.ndarray | None) -> tuple[dict, object]:
    cell = load_builtin_cell()
    opts = DemoOptions(seed=3, geometry_errors=False, calibrate=False)  # the placement alone
    tr = demo_truth(cell, opts)
    opts = replace(opts, truth=tr if T_err is None else replace(tr, part_placement_error=T_err))
    run_demo(out, opts)
    world = SimWorld(cell, demo_world(cell, opts))
    T = invert(cell.T_cell_part())
    centres = {k: T[:3, :3] @ h.position_m + T[:3, 3] for k, h in world.holes.items()}
    truth = true_evaluation(cell, centres, {k: h.diameter_m for k, h in world.holes.items()})
    return json.loads((out / "report.json").read_text()), truth


@pytest.mark.slow
def test_part_off_its_fixture_changes_nothing_in_the_datum_frame(tmp_path: Path) -> None:
    T_err = placement(1.5, 0.4)
    on, _ = _demo(tmp_path / "on", None)
    off, truth = _demo(tmp_path / "off", T_err)
    c_on = {c["id"]: c for c in on["characteristics"]}
    same = [abs(c["value_m"] - c_on[c["id"]]["value_m"]) <= np.hypot(c["U_m"], c_on[c["id"]]["U_m"])
            for c in off["characteristics"] if c["value_m"] is not None]  # fmt: skip
    assert len(same) == 80 and np.mean(same) >= 0.9
    assert placement_error(off["placement"], truth)["within_U"]
    assert np.linalg.norm(off["placement"]["T_fixture_part"]["xyz"]) == pytest.approx(
        1.5e-3, abs=2e-4
    )
