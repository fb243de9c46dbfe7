"""A cell calibration of the simulated cell from projected corners (no images).

For tests of the run side and benchmarks: the target's corners are projected through the
simulated cell's TRUE geometry (:class:`cell.sim.true_geometry.TrueGeometry`: D-H errors, the
head on the flange, the base and the plate as they truly are) at arm poses that look at the
plate (:func:`cell.calibration.synthetic.view_joints`), ``noise_px`` of corner noise and the
arm's repeatability as a per-view flange scatter are added, and the adjustment
(:func:`cell.calibration.solve.solve_calibration`) estimates the calibration from them with
the provenance of the run's cell. What this leaves out against a calibration from rendered
images (``calibrate_cell``): the corner detector's errors, the plate's collision-free tour,
and the true head's intrinsics being off its stereo file (the projection uses the file's).
"""

from __future__ import annotations

import numpy as np

from cell.calibration.model import State
from cell.calibration.observations import Cameras
from cell.calibration.solve import CalibrationResult, SolveOptions, solve_calibration
from cell.calibration.synthetic import SyntheticTruth, reference_joints, simulate, view_joints
from cell.config import CellConfig
from cell.errors import CellError
from cell.run.calibration import expected_provenance
from cell.sim.true_geometry import TrueGeometry
from cell.uncertainty.repeatability import sigma_per_axis_m
from measure import StereoCalibration, head_frame
from robots.transforms import invert

#: the flange scatter's rotation per axis is its position over this lever (m), as the
#: adjustment's own estimate assumes
SCATTER_LEVER_M = 0.5


def synthetic_truth(cell: CellConfig, geometry: TrueGeometry, stereo: StereoCalibration):
    """The simulated cell's truth as :class:`cell.calibration.synthetic.SyntheticTruth`."""
    if cell.calibration_target is None or geometry.T_cell_target is None:
        raise CellError(f"{cell.name}: the cell file has no calibration_target")
    nominal = cell.build_robot().dh
    true_rows = np.array(geometry.table.arrays()).T  # (6, 4): a, d, alpha, theta offset
    delta = (true_rows - np.array(nominal.arrays()).T).ravel()
    cameras = Cameras.from_stereo(stereo)
    state = State(
        T_tool0_camera=geometry.T_tool0_camera_left,
        T_base_target=invert(geometry.T_cell_base) @ geometry.T_cell_target,
        T_left_right=cameras.T_left_right,
        delta=delta,
    )
    return SyntheticTruth(nominal, cameras, state, cell.T_tool0_tcp() @ head_frame(stereo),
                          cell.calibration_target.target_spec())  # fmt: skip


def simulated_calibration(
    cell: CellConfig,
    geometry: TrueGeometry,
    stereo: StereoCalibration,
    repeatability_rp_m: float,
    n_views: int = 30,
    noise_px: float = 0.1,
    seed: int = 0,
) -> CalibrationResult:
    """The calibration of the simulated cell from ``n_views`` projected views (see the module
    docstring); raises the adjustment's refusals."""
    truth = synthetic_truth(cell, geometry, stereo)
    standoff = cell.tool.standoff_m
    q = view_joints(truth, n_views, (0.85 * standoff, 1.15 * standoff),
                    reference_joints(truth, standoff), seed=seed)  # fmt: skip
    s = sigma_per_axis_m(repeatability_rp_m)
    obs = simulate(truth, q, noise_px, seed=seed + 1, flange_sigma_m=s,
                   flange_sigma_rad=s / SCATTER_LEVER_M, source="simulated views")  # fmt: skip
    arm = cell.build_robot()
    return solve_calibration(obs, arm.dh, SolveOptions(), expected_provenance(cell, arm, stereo))
