"""Synthetic calibration data sets for the cell-calibration tests (known truth)."""

from __future__ import annotations

import csv
from pathlib import Path

import cv2
import numpy as np

from cell.calibration.estimate import (
    Cameras,
    SyntheticTruth,
    example_truth,
    seen_view_joints,
)
from measure.synth.heads import toed_in_stereo
from measure.synth.targets import render_target_pair
from robots.calibration import fk_with_errors

#: a small head for rendered images: 320 x 256 px, f = 400 px, 100 mm baseline
SMALL_STEREO = toed_in_stereo(image_size=(320, 256), pixel_m=2e-5, focal_m=8e-3)
#: the built-in cell's arm (tests that run the CLI with --cell use that cell file)
CELL_MODEL = "abb_irb2600_20_165"


def small_truth(seed: int = 0, stereo: bool = True, kinematic: bool = True) -> SyntheticTruth:
    """The example cell with the built-in cell's arm and the small head."""
    return example_truth(
        seed,
        stereo=stereo,
        kinematic=kinematic,
        model=CELL_MODEL,
        cameras=Cameras.from_stereo(SMALL_STEREO),
    )


def seen_views(truth: SyntheticTruth, n: int, seed: int, standoff=(0.2, 0.32)) -> np.ndarray:
    """Joints (n, 6) of views whose corners all fall inside every image."""
    Q = seen_view_joints(truth, n, standoff, seed)
    if len(Q) < n:
        raise ValueError(f"only {len(Q)} of {4 * n} views see the target")
    return Q


def write_rendered_set(
    truth: SyntheticTruth, Q: np.ndarray, folder: Path, joints: bool = True
) -> Path:
    """Render each view (left/right PNGs) and write poses.csv; returns the CSV path."""
    folder.mkdir(parents=True, exist_ok=True)
    T_bt = fk_with_errors(truth.dh, truth.truth.delta, Q)
    header = ["left_image", "right_image"] + (
        [f"q{i}_rad" for i in range(1, 7)]
        if joints
        else ["x_m", "y_m", "z_m", "qx", "qy", "qz", "qw"]
    )
    rows = []
    from scipy.spatial.transform import Rotation

    for i, q in enumerate(Q):
        T_left_plate = (
            np.linalg.inv(T_bt[i] @ truth.truth.T_tool0_camera) @ truth.truth.T_base_target
        )
        r = render_target_pair(true_head(truth), truth.target, T_left_plate, supersample=1, seed=i)
        cv2.imwrite(str(folder / f"L{i:02d}.png"), r.left)
        cv2.imwrite(str(folder / f"R{i:02d}.png"), r.right)
        pose = (
            list(q)
            if joints
            else [*T_bt[i][:3, 3], *Rotation.from_matrix(T_bt[i][:3, :3]).as_quat()]
        )
        rows.append([f"L{i:02d}.png", f"R{i:02d}.png", *(f"{v:.12g}" for v in pose)])
    path = folder / "poses.csv"
    with path.open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(header)
        w.writerows(rows)
    return path


def true_head(truth: SyntheticTruth):
    """The small head with the truth's stereo extrinsics (what the images show)."""
    from measure.calibration import StereoCalibration

    T_rl = np.linalg.inv(truth.truth.T_left_right)
    st = SMALL_STEREO
    return StereoCalibration(
        st.image_size, st.K_left, st.dist_left, st.K_right, st.dist_right, T_rl[:3, :3], T_rl[:3, 3]
    )
