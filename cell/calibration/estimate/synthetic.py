"""Simulated calibration data with a known truth: for tests, benchmarks and tour design.

:func:`random_truth` draws the hidden errors of a cell (D-H errors, the head's mount, the
target's placement, the stereo extrinsics) at realistic sizes; :func:`view_joints` finds arm
poses that look at the target; :func:`simulate` projects the target's corners through the
truth and adds pixel noise. Sizes (one sigma): D-H lengths ``dh_length_sigma_m``, D-H angles
``dh_angle_sigma_rad``, the head 1 mm and 0.3 deg, the target 1 mm and 0.05 deg, the right
camera 0.2 mm and 0.02 deg.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from cell.calibration.estimate.model import State, predict
from cell.calibration.estimate.observations import CalibrationObservations, CalibrationView, Cameras
from measure.target import TargetSpec
from robots.calibration import fk_with_errors
from robots.dh import DHTable
from robots.ik import solve_ik

Array = NDArray[np.float64]


@dataclass(frozen=True, eq=False)
class SyntheticTruth:
    """The hidden values of a simulated cell and its nominal starting point.

    ``cameras`` holds the intrinsics (exact) and the nominal ``T_left_right`` of the stereo
    calibration; ``truth`` the true unknowns; ``T_tool0_camera_nominal`` the drawing's mount.
    """

    dh: DHTable
    cameras: Cameras
    truth: State
    T_tool0_camera_nominal: Array
    target: TargetSpec


def _pose_error(rng: np.random.Generator, sigma_m: float, sigma_rad: float) -> Array:
    T = np.eye(4)
    T[:3, :3] = Rotation.from_rotvec(rng.normal(0.0, sigma_rad, 3)).as_matrix()
    T[:3, 3] = rng.normal(0.0, sigma_m, 3)
    return T


def random_truth(
    dh: DHTable,
    cameras: Cameras,
    target: TargetSpec,
    T_tool0_camera_nominal: Array,
    T_base_target_nominal: Array,
    seed: int = 0,
    dh_length_sigma_m: float = 3e-4,
    dh_angle_sigma_rad: float = np.deg2rad(0.02),
    kinematic: bool = True,
) -> SyntheticTruth:
    """Draw a truth around the nominal poses (see the module docstring for the sizes)."""
    rng = np.random.default_rng(seed)
    delta = np.zeros(24)
    if kinematic:
        sig = np.tile(
            [dh_length_sigma_m, dh_length_sigma_m, dh_angle_sigma_rad, dh_angle_sigma_rad], 6
        )
        delta = rng.normal(0.0, 1.0, 24) * sig
    X = T_tool0_camera_nominal @ _pose_error(rng, 1e-3, np.deg2rad(0.3))
    Y = T_base_target_nominal @ _pose_error(rng, 1e-3, np.deg2rad(0.05))
    L = None
    if cameras.T_left_right is not None:
        L = cameras.T_left_right @ _pose_error(rng, 2e-4, np.deg2rad(0.02))
    return SyntheticTruth(
        dh=dh,
        cameras=cameras,
        truth=State(T_tool0_camera=X, T_base_target=Y, T_left_right=L, delta=delta),
        T_tool0_camera_nominal=np.asarray(T_tool0_camera_nominal, float),
        target=target,
    )


def view_joints(
    truth: SyntheticTruth,
    n_views: int,
    standoff_m: tuple[float, float],
    q_ref: Array,
    seed: int = 0,
    max_tilt_rad: float = np.deg2rad(35.0),
    max_roll_rad: float = np.deg2rad(60.0),
    aim_spread_m: float = 0.02,
) -> Array:
    """Joints (n_views, 6) of views of the target from a standoff drawn in ``standoff_m``
    (min, max), aimed within ``aim_spread_m`` of its centre, tilted up to ``max_tilt_rad``
    about a random in-plane axis and rolled up to ``max_roll_rad`` about the view axis; of the
    IK solutions (nominal table), the one nearest ``q_ref``.

    All views at one standoff aimed at one point leave the arm's scale about the shoulder
    undetermined (it and the target's distance trade against the camera's depth): vary both.
    """
    rng = np.random.default_rng(seed)
    p = truth.target.object_points()
    centre = 0.5 * (p.min(axis=0) + p.max(axis=0))
    lower, upper = np.full(6, -np.pi), np.full(6, np.pi)
    out = []
    tries = 0
    while len(out) < n_views:
        tries += 1
        if tries > 50 * n_views:
            raise ValueError("cannot find views of the target within reach")
        az = rng.uniform(0, 2 * np.pi)
        tilt = max_tilt_rad * np.sqrt(rng.uniform(0.1, 1.0))
        R_tilt = Rotation.from_rotvec(tilt * np.array([np.cos(az), np.sin(az), 0.0]))
        roll = Rotation.from_rotvec([0, 0, rng.uniform(-max_roll_rad, max_roll_rad)])
        R_target_cam = R_tilt * roll  # the board frame's z into the plate: the camera's z
        T_target_cam = np.eye(4)
        T_target_cam[:3, :3] = R_target_cam.as_matrix()
        aim = centre + np.append(rng.uniform(-aim_spread_m, aim_spread_m, 2), 0.0)
        dist = rng.uniform(*standoff_m)
        T_target_cam[:3, 3] = aim - R_target_cam.as_matrix()[:, 2] * dist
        T_base_tool0 = (
            truth.truth.T_base_target @ T_target_cam @ np.linalg.inv(truth.truth.T_tool0_camera)
        )
        ik = solve_ik(truth.dh, T_base_tool0, lower, upper)
        if not ik.ok:
            continue
        best = ik.solutions[np.argmin(np.abs(ik.solutions - q_ref).sum(axis=1))]
        if np.abs(best - q_ref).max() > 1.5:
            continue
        out.append(best)
    return np.array(out)


def simulate(
    truth: SyntheticTruth,
    q_rad: Array,
    noise_px: float = 0.1,
    seed: int = 0,
    with_joints: bool = True,
    source: str = "<synthetic>",
    flange_sigma_m: float = 0.0,
    flange_sigma_rad: float = 0.0,
) -> CalibrationObservations:
    """Observations of the views ``q_rad`` (V, 6): exact corners plus N(0, noise_px) noise;
    an image where a corner falls outside holds ``None`` (target not seen).

    ``with_joints=False`` gives the true flange poses instead of the joints (no kinematics).
    ``flange_sigma_m``, ``flange_sigma_rad``: each view's flange is off by that much more (per
    axis, position and rotation about the flange's origin: the arm's repeatability), which the
    observations do not report.
    """
    rng = np.random.default_rng(seed)
    M = len(truth.target.object_points())
    V = len(q_rad)
    views = []
    for i in range(V):
        views.append(
            CalibrationView(
                name=f"view{i:02d}",
                corners_left_px=np.zeros((M, 2)),
                corners_right_px=np.zeros((M, 2)) if truth.cameras.stereo else None,
                q_rad=np.asarray(q_rad[i], float),
            )
        )
    T_bt = fk_with_errors(truth.dh, truth.truth.delta, q_rad)
    T_seen = T_bt.copy()
    if flange_sigma_m > 0 or flange_sigma_rad > 0:
        for i in range(V):
            dR = Rotation.from_rotvec(rng.normal(0.0, flange_sigma_rad, 3)).as_matrix()
            T_seen[i, :3, :3] = dR @ T_bt[i, :3, :3]
            T_seen[i, :3, 3] = T_bt[i, :3, 3] + rng.normal(0.0, flange_sigma_m, 3)
    views = [replace(v, q_rad=None, T_base_tool0=T_seen[i]) for i, v in enumerate(views)]
    blank = CalibrationObservations(tuple(views), truth.target, truth.cameras, source)
    pred = predict(blank, None, truth.truth, jac=False)
    exact = pred.residuals.reshape(-1, M, 2)  # corners minus zero
    n_left = V
    out = []
    w, h = truth.cameras.left.image_size

    def inside(c: Array) -> Array | None:
        ok = np.all((c >= 0) & (c <= (w - 1, h - 1)))
        return c if ok else None

    for i in range(V):
        left = inside(exact[i] + rng.normal(0.0, noise_px, (M, 2)))
        right = (
            inside(exact[n_left + i] + rng.normal(0.0, noise_px, (M, 2)))
            if truth.cameras.stereo
            else None
        )
        out.append(
            CalibrationView(
                name=f"view{i:02d}",
                corners_left_px=left,
                corners_right_px=right,
                q_rad=np.asarray(q_rad[i], float) if with_joints else None,
                T_base_tool0=None if with_joints else T_bt[i],
            )
        )
    return CalibrationObservations(tuple(out), truth.target, truth.cameras, source)


def example_truth(
    seed: int = 0,
    stereo: bool = True,
    kinematic: bool = True,
    model: str = "abb_irb1600_10_145",
    target: TargetSpec | None = None,
    cameras: Cameras | None = None,
) -> SyntheticTruth:
    """A ready cell: ``model`` on the origin, a plate 0.85 m in front of it at table height
    (0.25 m), face up, the standard toed-in head (:func:`measure.synth.heads.standard_stereo`)
    0.1 m below the flange, looking along ``tool0`` z. The plate's frame is the board frame of
    docs/conventions.md (z into the plate: down; the printed face, z = 0, faces -z: up), the
    frame the detected corners are ordered in (:func:`cell.calibration.capture.orient_chessboard`),
    so the truth and a calibration from images agree."""
    from measure.synth.heads import standard_stereo
    from robots.dh_models import dh_table

    cams = cameras or Cameras.from_stereo(standard_stereo())
    if not stereo:
        cams = Cameras(left=cams.left, source=cams.source)
    spec = target or TargetSpec("chessboard", 8, 6, 0.012)
    T_tool0_head = np.eye(4)
    T_tool0_head[:3, 3] = (0.0, 0.04, 0.10)
    T_head_left = np.eye(4)
    if cams.T_left_right is not None:  # the left camera half a baseline left, toed in
        b = cams.T_left_right[:3, 3]
        T_head_left[:3, :3] = Rotation.from_rotvec(
            [0, np.arctan2(np.linalg.norm(b) / 2, 0.25), 0]
        ).as_matrix()
        T_head_left[:3, 3] = -0.5 * b
    T_base_target = np.eye(4)
    T_base_target[:3, :3] = Rotation.from_rotvec([np.pi, 0, 0]).as_matrix()  # z down
    T_base_target[:3, 3] = (0.85, 0.02, 0.25)
    return random_truth(
        dh_table(model),
        cams,
        spec,
        T_tool0_head @ T_head_left,
        T_base_target,
        seed=seed,
        kinematic=kinematic,
    )


def reference_joints(truth: SyntheticTruth, standoff_m: float = 0.25) -> Array:
    """The joints (6,) of the straight view of the target's centre with the smallest norm."""
    p = truth.target.object_points()
    centre = 0.5 * (p.min(axis=0) + p.max(axis=0))
    T_target_cam = np.eye(4)
    T_target_cam[:3, 3] = centre - np.array([0, 0, standoff_m])  # in front of the face (-z)
    T = truth.truth.T_base_target @ T_target_cam @ np.linalg.inv(truth.truth.T_tool0_camera)
    ik = solve_ik(truth.dh, T, np.full(6, -np.pi), np.full(6, np.pi))
    if not ik.ok:
        raise ValueError(f"the straight view is out of reach: {ik.reason}")
    return ik.solutions[np.argmin(np.linalg.norm(ik.solutions, axis=1))]


def seen_view_joints(
    truth: SyntheticTruth,
    n: int,
    standoff_m: tuple[float, float],
    seed: int,
    lower: Array | None = None,
    upper: Array | None = None,
) -> Array:
    """Joints (at most n, 6) of views whose every corner falls inside every image: ``4 n``
    views drawn by :func:`view_joints` about :func:`reference_joints`, those outside the joint
    limits ``lower``/``upper`` (rad, if given) dropped, the first ``n`` that see the target
    kept (the caller decides what too few means)."""
    Q = view_joints(truth, 4 * n, standoff_m, reference_joints(truth), seed=seed)
    if lower is not None and upper is not None:
        Q = Q[np.all((lower <= Q) & (upper >= Q), axis=1)]
    obs = simulate(truth, Q, 0.0)
    ok = [
        i
        for i, v in enumerate(obs.views)
        if v.corners_left_px is not None
        and (not truth.cameras.stereo or v.corners_right_px is not None)
    ]
    return Q[ok[:n]]


def truth_in_gauge(truth: SyntheticTruth) -> State:
    """The truth as the calibration can see it: the structurally redundant D-H terms folded
    into the target's and the camera's poses (``robots.calibration.redundancy.fold_redundant``)."""
    from robots.calibration.redundancy import fold_redundant

    delta, C, E = fold_redundant(truth.dh, truth.truth.delta)
    return State(
        T_tool0_camera=E @ truth.truth.T_tool0_camera,
        T_base_target=np.linalg.inv(C) @ truth.truth.T_base_target,
        T_left_right=truth.truth.T_left_right,
        delta=delta,
    )


def parameter_errors(cal, truth: State) -> dict[str, float]:
    """Estimate minus truth of every free parameter of a calibration (m, rad), in the
    calibration's perturbation (position difference; rotation vector of ``R_est R_true^T``)."""
    from robots.calibration import term_names

    out: dict[str, float] = {}
    poses = {
        "T_tool0_camera": (cal.T_tool0_camera.T, truth.T_tool0_camera),
        "T_base_target": (cal.T_base_target.T, truth.T_base_target),
    }
    if cal.T_left_right is not None and truth.T_left_right is not None:
        poses["T_left_right"] = (cal.T_left_right.T, truth.T_left_right)
    for prefix, (est, true) in poses.items():
        dv = est[:3, 3] - true[:3, 3]
        dw = Rotation.from_matrix(est[:3, :3] @ true[:3, :3].T).as_rotvec()
        for c, v in zip(
            ("x_m", "y_m", "z_m", "rx_rad", "ry_rad", "rz_rad"), (*dv, *dw), strict=True
        ):
            out[f"{prefix}.{c}"] = float(v)
    for k, n in enumerate(term_names()):
        out[f"dh.{n}"] = float(cal.delta[k] - truth.delta[k])
    return {n: out[n] for n in cal.parameter_names}
