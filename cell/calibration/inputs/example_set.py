"""A synthetic data set to try ``holecell calibrate hand-eye`` on: rendered images, poses, camera.

:func:`write_example_set` draws a cell with known hidden errors
(:func:`cell.calibration.estimate.synthetic.example_truth`: the built-in cell's arm with D-H
errors, a stereo head on the flange, a chessboard 8 x 6 inner corners of 12 mm in front of the arm),
chooses arm poses that show the whole board in both cameras, renders each view
(:func:`measure.synth.targets.render_target_pair`: blur and sensor noise) and writes, into a
new folder:

- ``L00.png``, ``R00.png``, ... (stereo) or ``view00.png``, ... (mono): 640 x 512 px, 8 bit;
- ``poses.csv``: ``left_image,right_image`` (or ``image``) and ``q1_rad..q6_rad`` (the joints,
  for ``--cell``) or, with ``joints=False``, the flange pose ``x_m,y_m,z_m,qx,qy,qz,qw``;
- ``stereo.json`` (the head's nominal calibration, for ``--stereo``) or ``intrinsics.yaml``
  (the camera, OpenCV FileStorage, for ``--intrinsics``);
- ``truth.json``: what the calibration should find (``T_tool0_camera``, ``T_base_target``, m;
  the D-H errors, m and rad, with the redundant terms folded into the poses as the
  calibration sees them; :func:`cell.calibration.estimate.synthetic.truth_in_gauge`).
"""

from __future__ import annotations

import csv
import json
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from cell.calibration.errors import CalibrationDataError
from cell.calibration.estimate.observations import Cameras
from cell.calibration.estimate.synthetic import (
    SyntheticTruth,
    example_truth,
    seen_view_joints,
    truth_in_gauge,
)
from measure.calibration import StereoCalibration
from measure.synth.heads import toed_in_stereo
from measure.synth.targets import render_target_pair
from measure.target import TargetSpec
from robots.calibration import fk_with_errors, term_names
from robots.files import write_text_atomic

Array = NDArray[np.float64]

#: the example's head: 640 x 512 px, f = 800 px, 100 mm baseline, toed in to 250 mm
EXAMPLE_HEAD = toed_in_stereo(image_size=(640, 512), pixel_m=1e-5, focal_m=8e-3)
#: the built-in cell's arm, so that ``--cell motorcycle_frame`` gives its kinematics
EXAMPLE_MODEL = "abb_irb2600_20_165"
#: the board: what ``--cols 8 --rows 6 --pitch 0.012`` describe
EXAMPLE_BOARD = TargetSpec("chessboard", 8, 6, 0.012)
#: the range of distances of the views from the board (m)
STANDOFF_M = (0.2, 0.32)


@dataclass(frozen=True)
class ExampleSet:
    """The files written by :func:`write_example_set`."""

    folder: Path
    poses: Path
    camera: Path
    truth: Path
    views: int
    stereo: bool
    joints: bool

    def command(self) -> str:
        """The ``holecell calibrate hand-eye`` command line that calibrates from this set."""
        cam = f"--stereo {self.camera}" if self.stereo else f"--intrinsics {self.camera}"
        cell = " --cell motorcycle_frame" if self.joints else ""
        b = EXAMPLE_BOARD
        return (
            f"holecell calibrate hand-eye --images {self.folder} --poses {self.poses} {cam}"
            f"{cell} --cols {b.cols} --rows {b.rows} --pitch {b.pitch_m:g} "
            f"-o {self.folder / 'cellcal.json'}"
        )


def _seen_joints(truth: SyntheticTruth, n: int, seed: int, lower: Array, upper: Array) -> Array:
    """Joints (n, 6) of views showing every corner in every camera, within the limits."""
    Q = seen_view_joints(truth, n, STANDOFF_M, seed, lower, upper)
    if len(Q) < n:
        raise CalibrationDataError(
            "--views", f"only {len(Q)} of {4 * n} drawn views show the whole board; ask fewer"
        )
    return Q


def _true_head(truth: SyntheticTruth) -> StereoCalibration:
    """The head with the truth's extrinsics (what the images show; stereo.json is nominal)."""
    h = EXAMPLE_HEAD
    if truth.truth.T_left_right is None:
        return h
    T_rl = np.linalg.inv(truth.truth.T_left_right)
    return StereoCalibration(
        h.image_size, h.K_left, h.dist_left, h.K_right, h.dist_right, T_rl[:3, :3], T_rl[:3, 3]
    )


def _write_intrinsics(path: Path) -> None:
    h = EXAMPLE_HEAD
    fs = cv2.FileStorage(str(path), cv2.FILE_STORAGE_WRITE)
    fs.write("image_width", int(h.image_size[0]))
    fs.write("image_height", int(h.image_size[1]))
    fs.write("camera_matrix", np.asarray(h.K_left, float))
    fs.write("distortion_coefficients", np.asarray(h.dist_left, float).reshape(1, -1))
    fs.release()


def _write_truth(path: Path, truth: SyntheticTruth, joints: bool) -> None:
    g = truth_in_gauge(truth) if joints else truth.truth
    doc = {
        "about": "the hidden values of this synthetic set: what the calibration should find",
        "T_tool0_camera": np.asarray(g.T_tool0_camera).tolist(),
        "T_base_target": np.asarray(g.T_base_target).tolist(),
    }
    if joints:
        doc["dh_errors"] = dict(zip(term_names(), map(float, g.delta), strict=True))
    if g.T_left_right is not None:
        doc["T_left_right"] = np.asarray(g.T_left_right).tolist()
    write_text_atomic(path, json.dumps(doc, indent=1) + "\n")


def write_example_set(
    folder: str | Path, views: int = 12, seed: int = 0, stereo: bool = True, joints: bool = True
) -> ExampleSet:
    """Write a synthetic set of ``views`` views into the new (or empty) ``folder``; see the
    module docstring. ``joints=False``: flange poses in the CSV, no kinematic errors."""
    from cell.config import load_builtin_cell

    out = Path(folder)
    if out.exists() and (not out.is_dir() or any(out.iterdir())):
        raise CalibrationDataError(str(out), "exists and is not an empty folder: nothing written")
    if not 3 <= views <= 200:
        raise CalibrationDataError("--views", f"{views}: give 3 to 200 views")
    arm = load_builtin_cell().build_robot()
    truth = example_truth(
        seed, stereo=stereo, kinematic=joints, model=EXAMPLE_MODEL,
        cameras=Cameras.from_stereo(EXAMPLE_HEAD), target=EXAMPLE_BOARD,
    )  # fmt: skip
    Q = _seen_joints(truth, views, seed, arm.lower, arm.upper)
    T_bt = fk_with_errors(truth.dh, truth.truth.delta, Q)
    head = _true_head(truth)
    out.mkdir(parents=True, exist_ok=True)
    images = ["left_image", "right_image"] if stereo else ["image"]
    pose_cols = (
        [f"q{i}_rad" for i in range(1, 7)]
        if joints
        else ["x_m", "y_m", "z_m", "qx", "qy", "qz", "qw"]
    )
    rows = []
    for i, q in enumerate(Q):
        T_left_plate = (
            np.linalg.inv(T_bt[i] @ truth.truth.T_tool0_camera) @ truth.truth.T_base_target
        )
        r = render_target_pair(head, EXAMPLE_BOARD, T_left_plate, supersample=1, seed=seed + i)
        names = [f"L{i:02d}.png", f"R{i:02d}.png"] if stereo else [f"view{i:02d}.png"]
        for name, img in zip(names, (r.left, r.right), strict=False):
            cv2.imwrite(str(out / name), img)
        T = T_bt[i]
        pose = list(q) if joints else [*T[:3, 3], *Rotation.from_matrix(T[:3, :3]).as_quat()]
        rows.append([*names, *(f"{v:.12g}" for v in pose)])
    poses = out / "poses.csv"
    with poses.open("w", newline="", encoding="utf-8") as fh:
        w = csv.writer(fh)
        w.writerow([*images, *pose_cols])
        w.writerows(rows)
    camera = out / ("stereo.json" if stereo else "intrinsics.yaml")
    if stereo:
        EXAMPLE_HEAD.save(camera)
    else:
        _write_intrinsics(camera)
    _write_truth(out / "truth.json", truth, joints)
    return ExampleSet(out, poses, camera, out / "truth.json", len(Q), stereo, joints)
