"""The demo's first step: calibrate the simulated cell, and how good that calibration is.

:func:`calibrate_demo_cell` calibrates the simulated cell (:mod:`cell.run.sim_calibration`:
the plate's corners projected through the simulated cell's true geometry at views of the
plate chosen over the hole tour's joint range, corner noise and the arm's repeatability added,
one adjustment), writes
``RUN_DIR/cellcal.json`` and measures the estimate against the simulation's truth (the
hand-eye in the calibration's gauge: the structurally redundant D-H terms folded into it,
:func:`cell.calibration.synthetic.truth_in_gauge`).
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from cell.calibration.modelfile import save_calibration
from cell.calibration.result import CellCalibration
from cell.calibration.solve import pose_error
from cell.calibration.synthetic import truth_in_gauge
from cell.config import CellConfig
from cell.run.calibration import RUN_FILENAME
from cell.run.sim_calibration import design_views, simulated_calibration, synthetic_truth
from cell.sim.session import SimCell
from planner import Tour


@dataclass(frozen=True)
class DemoCalibration:
    """The demo's calibration: the file, its estimate, the wall time (s), the hand-eye's error
    against the truth (m, rad), the D-H terms fixed and the method."""

    path: Path
    calibration: CellCalibration
    seconds: float
    hand_eye_error_m: float
    hand_eye_error_rad: float
    fixed_terms: tuple[str, ...]
    method: str

    @property
    def hand_eye_sigma_m(self) -> float:
        """Root sum of the hand-eye's position variances (m)."""
        return float(np.linalg.norm(self.calibration.T_tool0_camera.sigma_xyz_m))

    @property
    def hand_eye_sigma_rad(self) -> float:
        """Root sum of the hand-eye's rotation variances (rad)."""
        return float(np.linalg.norm(self.calibration.T_tool0_camera.sigma_rot_rad))


def calibrate_demo_cell(
    sim: SimCell, cell: CellConfig, tour: Tour, run_dir: Path, views: int, seed: int
) -> DemoCalibration:
    """Calibrate the simulated cell of ``sim`` for the hole tour ``tour`` (its joint range)
    and write ``run_dir/cellcal.json``."""
    t0 = time.perf_counter()
    geometry = sim.world.true_geometry()
    stereo = sim.camera.stereo
    q_views = design_views(cell, stereo, np.array([s.q for s in tour.stops]), views)
    res = simulated_calibration(cell, geometry, stereo, sim.world.truth.repeatability_rp_m,
                                q_views, seed=seed)  # fmt: skip
    path = Path(run_dir) / RUN_FILENAME
    save_calibration(res.calibration, path)
    seconds = time.perf_counter() - t0
    gauge = truth_in_gauge(synthetic_truth(cell, geometry, stereo))
    dp, dr = pose_error(res.calibration.T_tool0_camera.T, gauge.T_tool0_camera)
    fixed = tuple(t.name for t in res.calibration.dh_terms if not t.free)
    method = (f"{len(q_views)} views of the plate (planner's feasible views; corners projected "
              "through the simulated cell, not rendered)")  # fmt: skip
    return DemoCalibration(path, res.calibration, seconds, dp, dr, fixed, method)
