"""A cell calibration of the simulated cell from projected corners (no images).

For tests of the run side and benchmarks: the target's corners are projected through the
simulated cell's TRUE geometry (:class:`cell.sim.true_geometry.TrueGeometry`: D-H errors, the
head on the flange, the base and the plate as they truly are) at arm poses that look at the
plate (given, e.g. a planned calibration tour's stops, or :func:`design_views`: the
calibration planner's feasible, collision-free views, pre-selected for rotations, image cover
and the hole tour's joint range), ``noise_px`` of corner noise and the arm's repeatability as
a per-view flange scatter are added, and the adjustment
(:func:`cell.calibration.estimate.solve.solve_calibration`) estimates the calibration from them with
the provenance of the run's cell. What this leaves out against a calibration from rendered
images (``calibrate_cell``): the corner detector's errors, the time to drive the tour, and
the true head's intrinsics being off its stereo file (the projection uses the file's; the
right camera's pose it takes from the true head when given one).
"""

from __future__ import annotations

import numpy as np

from cell.calibration.estimate import (
    CalibrationResult,
    Cameras,
    SolveOptions,
    State,
    SyntheticTruth,
    simulate,
    solve_calibration,
)
from cell.calibration.use import expected_provenance
from cell.config import CellConfig
from cell.errors import CellError
from cell.sim.true_geometry import TrueGeometry
from cell.uncertainty.repeatability import sigma_per_axis_m
from measure import StereoCalibration, head_frame
from robots.transforms import invert

#: the flange scatter's rotation per axis is its position over this lever (m), as the
#: adjustment's own estimate assumes
SCATTER_LEVER_M = 0.5


def synthetic_truth(
    cell: CellConfig,
    geometry: TrueGeometry,
    stereo: StereoCalibration,
    true_stereo: StereoCalibration | None = None,
) -> SyntheticTruth:
    """The simulated cell's truth as :class:`cell.calibration.estimate.synthetic.SyntheticTruth`:
    the intrinsics of ``stereo`` (the file's, as the adjustment takes them), the right camera
    where ``true_stereo`` (the simulated head as it truly is) puts it, else the file's."""
    if cell.calibration_target is None or geometry.T_cell_target is None:
        raise CellError(f"{cell.name}: the cell file has no calibration_target")
    nominal = cell.build_robot().dh
    true_rows = np.array(geometry.table.arrays()).T  # (6, 4): a, d, alpha, theta offset
    delta = (true_rows - np.array(nominal.arrays()).T).ravel()
    cameras = Cameras.from_stereo(stereo)
    true_lr = Cameras.from_stereo(true_stereo).T_left_right if true_stereo else None
    state = State(
        T_tool0_camera=geometry.T_tool0_camera_left,
        T_base_target=invert(geometry.T_cell_base) @ geometry.T_cell_target,
        T_left_right=cameras.T_left_right if true_lr is None else true_lr,
        delta=delta,
    )
    return SyntheticTruth(nominal, cameras, state, cell.T_tool0_tcp() @ head_frame(stereo),
                          cell.calibration_target.target_spec())  # fmt: skip


def design_views(cell: CellConfig, stereo: StereoCalibration, stops_q: np.ndarray,
                 n_views: int) -> np.ndarray:  # fmt: skip
    """Joints (n, 6) of ``n_views`` views of the cell's plate: the calibration planner's
    feasible views (both cameras see the whole board, IK within limits, no collision),
    pre-selected geometrically over the joint range of the hole tour's stops ``stops_q``
    (:func:`planner.calibration.preselect`; the I-optimal design of ``holecell
    plan-calibration`` chooses better and takes a minute)."""
    from cell.calibration.plan import board_of, cell_target, joint_range, stereo_model
    from planner.calibration import candidate_views, preselect

    head = stereo_model(stereo)
    cands = candidate_views(cell.build_arm(), board_of(cell_target(cell)), head,
                            cell.tool.standoff_m, cell.home_q())  # fmt: skip
    rows = preselect(cands, n_views, head.image_size, joint_range(stops_q))
    return cands.q[rows]


def simulated_calibration(
    cell: CellConfig,
    geometry: TrueGeometry,
    stereo: StereoCalibration,
    repeatability_rp_m: float,
    q_views: np.ndarray,
    noise_px: float = 0.1,
    seed: int = 0,
    true_stereo: StereoCalibration | None = None,
) -> CalibrationResult:
    """The calibration of the simulated cell from views at joints ``q_views`` (V, 6) (see
    the module docstring; ``true_stereo``: the simulated head as it truly is, whose right
    camera the projection uses); raises the adjustment's refusals."""
    truth = synthetic_truth(cell, geometry, stereo, true_stereo)
    q = np.asarray(q_views, float)
    s = sigma_per_axis_m(repeatability_rp_m)
    obs = simulate(truth, q, noise_px, seed=seed + 1, flange_sigma_m=s,
                   flange_sigma_rad=s / SCATTER_LEVER_M, source="simulated views")  # fmt: skip
    arm = cell.build_robot()
    return solve_calibration(obs, arm.dh, SolveOptions(), expected_provenance(cell, arm, stereo))
