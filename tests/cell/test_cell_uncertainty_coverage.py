"""Honest uncertainty on simulated captures: the simulator knows the truth.

The small cell's holes are captured from their planned stops on a simulated cell whose arm
scatters by its data-sheet repeatability, whose true stereo head is off its calibration by a
draw from the calibration's uncertainty, and whose part stands at 24 degC with a true expansion
coefficient off the material's figure; the run is given a noisy thermometer reading. Over eight
such cells (24 holes, 48 characteristics) the true value lies within U (k = 2) for 90-100 %
of them, and U is not inflated: fewer than 90 % lie within U / 2. (The thermal model's share
is checked over whole runs in ``benchmarks/uncertainty_coverage.py``.)"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from cell_fixtures import SmallCell, steady_drift

from cell.camera import cell_stereo
from cell.demo.demo import truth_error
from cell.run.inspect import inspect_hole
from cell.sim.camera import SimCamera
from cell.sim.truth import CellTruth
from cell.sim.world import SimWorld, WorldOptions
from cell.uncertainty.context import budget_context
from cell.uncertainty.part_temperature import part_state
from cell.uncertainty.repeatability import repeatability_rp_m


class _Arm:
    """Stands in for the controller: the joints the camera is triggered at."""

    def __init__(self) -> None:
        self.q = np.zeros(6)

    def q_rad(self) -> np.ndarray:
        return self.q


def _run(sc: SmallCell, seed: int):
    cell = sc.cell
    rp, _ = repeatability_rp_m(cell.robot.model, None)
    mat, _ = cell.part_material()
    alpha = mat.alpha_per_K + np.random.default_rng(seed).normal(0.0, mat.u_alpha_per_K)
    truth = replace(CellTruth.zero(seed), repeatability_rp_m=rp, calibration_sigma_scale=1.0,
                    part_temperature_c=24.0)  # fmt: skip
    opts = WorldOptions(drift=steady_drift(), truth=truth,
                        part_alpha_per_K=alpha, part_thermometer_sigma_K=0.1)  # fmt: skip
    world = SimWorld(cell, opts)
    ctrl = _Arm()
    stereo = cell_stereo(cell)
    cam = SimCamera(world, ctrl, stereo, seed=seed)
    ctx = budget_context(cell, stereo, part_state(cell, world.part_reading_c(), 0.2))
    arm = cell.build_arm()
    holes = {h.id: h for h in cell.holes_in_cell()}
    results = []
    for k, stop in enumerate(sc.tour.stops):
        ctrl.q = np.asarray(stop.q, float)
        pair = cam.capture()
        temps = world.temperatures(0.0)
        r, _ = inspect_hole(cell, arm, None, stereo, holes[stop.hole_id], k, pair.left,
                            pair.right, ctrl.q, temps, 0.0, ctx)  # fmt: skip
        results.append(r)
    return world, results


def test_truth_lies_within_U_for_most_holes(small_cell: SmallCell) -> None:
    within, within_half = [], []
    for seed in range(8):
        world, results = _run(small_cell, seed)
        tr = truth_error(world, results)
        assert tr.n == len(small_cell.tour.stops)
        within += tr.position_covered + tr.diameter_covered
        halved = [replace(r, U_position_m=r.U_position_m / 2, U_diameter_m=r.U_diameter_m / 2)
                  for r in results]  # fmt: skip
        half = truth_error(world, halved)
        within_half += half.position_covered + half.diameter_covered
    cov = float(np.mean(within))
    assert 0.90 <= cov <= 1.0, cov
    assert float(np.mean(within_half)) < 0.90, float(np.mean(within_half))
