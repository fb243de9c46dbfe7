"""Readers of public real hand-eye data sets, written into the input of ``holecell calibrate
hand-eye``: a pose CSV, an OpenCV FileStorage intrinsics file and the board.

Nothing here downloads anything: each reader takes the folder the data set was fetched into.

Data sets (see ``docs/calibration_real_data.md`` for sources, licences and commits):

- ``visp``: ViSP's eye-in-hand sample (``apps/calibration/hand-eye/data-eye-in-hand`` of
  ``lagadic/visp``): a Franka arm with a camera on its flange, 8 views of a 9 × 6 inner-corner
  chessboard of 23.6 mm squares (``chessboard-data.txt``), ``franka_image-<i>.png`` and
  ``franka_pose_rPe_<i>.yaml``: the end-effector pose in the robot base, a ViSP
  ``vpPoseVector`` ``[tx, ty, tz, θux, θuy, θuz]`` (metres, axis-angle radians) giving
  ``T_base_tool0`` (ViSP's ``rMe`` maps end-effector coordinates into the base, as our
  ``T_a_b``). Intrinsics ship in ``franka_camera.xml`` (px, py, u0, v0; no distortion: the
  camera's factory values).
- ``kuka``: the three real sets of Ali et al., Sensors 19(12) 2837, 2019 (``Datasets/kuka_<n>``
  of ``ihtishamaliktk/RWHE-Calib``): images in name order paired with the rows of
  ``RobotPosesVec.txt``, one row-major 4 × 4 ``T_base_tool0`` per line in metres (the
  authors' ``tcpPoseInBaseCoords``), the square side in ``squaresize.txt`` (``"20mm"``). The
  inner-corner count is not shipped (their MATLAB detector finds it); it is given here
  (``KUKA_BOARDS``). No intrinsics ship: they are calibrated from the same images with OpenCV
  (``calibrateCamera``, 5-term distortion), as the authors calibrate theirs from them.

Units on output: metres, quaternions ``x, y, z, w`` with ``w >= 0``.
"""

from __future__ import annotations

import csv
import glob
import os
import re
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np
import yaml
from scipy.spatial.transform import Rotation

#: inner corners (cols, rows) and square side of the KUKA sets' chessboards, found by detection
#: (the authors' files give only the square side); kuka_3's board is a ChArUco board
KUKA_BOARDS = {
    "kuka_1": ("chessboard", 28, 17),
    "kuka_2": ("chessboard", 24, 17),
    "kuka_3": ("charuco", 11, 8),
}


class DataSetError(ValueError):
    """A data-set folder that cannot be read: the message names the file and the field."""


@dataclass(frozen=True)
class Board:
    """The board as the CLI takes it: ``--pattern --cols --rows --pitch`` (inner corners, m)."""

    pattern: str
    cols: int
    rows: int
    pitch_m: float


@dataclass(frozen=True)
class HandEyeSet:
    """One data set, read: views in order, each an image path and ``T_base_tool0`` (4 × 4, m).

    ``K``/``dist`` are the intrinsics (``None`` when the set ships none). ``published`` is the
    authors' ``T_tool0_camera`` (4 × 4, m) and ``published_base_board`` their ``T_base_board``
    when the set's documentation gives them (else ``None``).
    """

    name: str
    folder: Path
    images: list[Path]
    T_base_tool0: list[np.ndarray]
    board: Board
    K: np.ndarray | None
    dist: np.ndarray | None
    published: np.ndarray | None = None
    published_base_board: np.ndarray | None = None


def pose_matrix(R: np.ndarray, t_m: np.ndarray) -> np.ndarray:
    """A 4 × 4 pose from a rotation matrix and a translation (m)."""
    T = np.eye(4)
    T[:3, :3] = R
    T[:3, 3] = np.asarray(t_m, dtype=float).ravel()
    return T


def _visp_vector(path: Path) -> np.ndarray:
    """The 6 numbers of a ViSP ``vpPoseVector`` YAML file (``data: [[tx], ...]``)."""
    try:
        doc = yaml.safe_load(path.read_text())
        vec = np.array([float(np.ravel(v)[0]) for v in doc["data"]])
    except (OSError, yaml.YAMLError, KeyError, TypeError, ValueError, IndexError) as exc:
        raise DataSetError(f"{path}: not a ViSP pose vector ({exc})") from None
    if vec.shape != (6,) or not np.all(np.isfinite(vec)):
        raise DataSetError(f"{path}: 'data' must hold 6 finite numbers, got {vec.tolist()}")
    return vec


def visp_pose(vec: np.ndarray) -> np.ndarray:
    """``[tx, ty, tz, θux, θuy, θuz]`` (m, rad) as a 4 × 4 pose."""
    return pose_matrix(Rotation.from_rotvec(vec[3:]).as_matrix(), vec[:3])


#: the eye-in-hand answer printed in ViSP's tutorial (doc/tutorial/calibration/
#: tutorial-calibration-extrinsic-eye-in-hand.dox), ``franka_ePc.txt`` and ``franka_rPo.txt``
VISP_PUBLISHED_T_TOOL0_CAMERA = np.array(
    [
        [-0.01100860563, -0.9999153181, 0.006940255266, 0.05771480338],
        [0.9999285371, -0.01097586361, 0.004738265792, -0.03392606387],
        [-0.004661689251, 0.006991920994, 0.9999646902, -0.04227445451],
        [0.0, 0.0, 0.0, 1.0],
    ]
)
VISP_PUBLISHED_T_BASE_BOARD = np.array(
    [
        [0.00556214, -0.999952, 0.00811517, 0.536486],
        [-0.999928, -0.00564766, -0.0105542, 0.123946],
        [0.0105996, -0.00805588, -0.999911, 0.0915574],
        [0.0, 0.0, 0.0, 1.0],
    ]
)


def _visp_intrinsics(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """``K`` and zero distortion from a ViSP camera XML (perspective model with distortion)."""
    try:
        model = ET.parse(path).getroot().find("camera/model")
        get = {k: float(model.find(k).text) for k in ("px", "py", "u0", "v0", "kud")}
    except (OSError, ET.ParseError, AttributeError, TypeError, ValueError) as exc:
        raise DataSetError(f"{path}: no camera/model px, py, u0, v0, kud ({exc})") from None
    if get["kud"] != 0.0:
        raise DataSetError(f"{path}: kud = {get['kud']} (ViSP's radial model is not OpenCV's)")
    K = np.array([[get["px"], 0, get["u0"]], [0, get["py"], get["v0"]], [0, 0, 1.0]])
    return K, np.zeros(5)


def read_visp(folder: Path) -> HandEyeSet:
    """ViSP's ``data-eye-in-hand`` folder (see the module docstring)."""
    board_txt = folder / "chessboard-data.txt"
    try:
        text = board_txt.read_text()
    except OSError as exc:
        raise DataSetError(f"{board_txt}: {exc.strerror}") from None
    size = re.search(r"(\d+)\s*x\s*(\d+)", text)
    side = re.search(r"square size:\s*([0-9.]+)\s*m", text)
    if not size or not side:
        raise DataSetError(f"{board_txt}: no 'W x H' and 'square size: S m' lines")
    board = Board("chessboard", int(size[1]), int(size[2]), float(side[1]))
    images, poses = [], []
    for img in sorted(folder.glob("franka_image-*.png"), key=lambda p: _index(p.name)):
        i = _index(img.name)
        images.append(img)
        poses.append(visp_pose(_visp_vector(folder / f"franka_pose_rPe_{i}.yaml")))
    if not images:
        raise DataSetError(f"{folder}: no franka_image-<i>.png")
    K, dist = _visp_intrinsics(folder / "franka_camera.xml")
    return HandEyeSet(
        "visp_franka",
        folder,
        images,
        poses,
        board,
        K,
        dist,
        VISP_PUBLISHED_T_TOOL0_CAMERA,
        VISP_PUBLISHED_T_BASE_BOARD,
    )


def _index(name: str) -> int:
    m = re.findall(r"\d+", name)
    if not m:
        raise DataSetError(f"{name}: no view number in the file name")
    return int(m[-1])


def _square_side_m(folder: Path) -> float:
    hits = sorted(glob.glob(str(folder / "s*size.txt")))  # kuka_3 spells it 'sqauresize.txt'
    if not hits:
        raise DataSetError(f"{folder}: no squaresize.txt")
    raw = Path(hits[0]).read_text().strip().lower()
    m = re.fullmatch(r"([0-9.]+)\s*(mm|m)", raw)
    if not m:
        raise DataSetError(f"{hits[0]}: square size {raw!r} is not '<number>mm' or '<number>m'")
    return float(m[1]) * (1e-3 if m[2] == "mm" else 1.0)


def read_kuka(folder: Path) -> HandEyeSet:
    """One ``Datasets/kuka_<n>`` folder of RWHE-Calib (see the module docstring)."""
    name = folder.name
    if name not in KUKA_BOARDS:
        raise DataSetError(f"{folder}: not one of {sorted(KUKA_BOARDS)}")
    rows_path = folder / "RobotPosesVec.txt"
    try:
        vec = np.loadtxt(rows_path, ndmin=2)
    except (OSError, ValueError) as exc:
        raise DataSetError(f"{rows_path}: {exc}") from None
    if vec.shape[1] != 16:
        raise DataSetError(f"{rows_path}: {vec.shape[1]} numbers a row, 16 expected (4 x 4)")
    poses = [v.reshape(4, 4) for v in vec]  # row-major, as the authors' reshape(v,4,[])'
    for i, T in enumerate(poses, start=1):
        if not np.allclose(T[3], [0, 0, 0, 1]) or np.abs(T[:3, 3]).max() > 10.0:
            raise DataSetError(f"{rows_path} row {i}: not a 4 x 4 pose in metres")
    images = sorted(p for ext in ("png", "bmp", "jpg") for p in folder.glob(f"*.{ext}"))
    if len(images) != len(poses):
        raise DataSetError(f"{folder}: {len(images)} images but {len(poses)} pose rows")
    kind, cols, rows = KUKA_BOARDS[name]
    return HandEyeSet(
        name, folder, images, poses, Board(kind, cols, rows, _square_side_m(folder)), None, None
    )


def read_set(kind: str, folder: str | os.PathLike) -> HandEyeSet:
    """``kind`` is ``visp`` or ``kuka``."""
    path = Path(folder)
    if not path.is_dir():
        raise DataSetError(f"{path}: not a folder")
    readers = {"visp": read_visp, "kuka": read_kuka}
    if kind not in readers:
        raise DataSetError(f"data-set kind {kind!r}: one of {sorted(readers)}")
    return readers[kind](path)


def quat_xyzw(R: np.ndarray) -> np.ndarray:
    """Unit quaternion ``x, y, z, w`` with ``w >= 0``."""
    q = Rotation.from_matrix(R).as_quat()
    return -q if q[3] < 0 else q


def write_poses_csv(path: Path, ds: HandEyeSet) -> None:
    """``image,x_m,y_m,z_m,qx,qy,qz,qw``: the flange (tool0) pose in the robot base."""
    with open(path, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["image", "x_m", "y_m", "z_m", "qx", "qy", "qz", "qw"])
        for img, T in zip(ds.images, ds.T_base_tool0, strict=True):
            q = quat_xyzw(T[:3, :3])
            w.writerow([img.name, *(f"{v:.9f}" for v in T[:3, 3]), *(f"{v:.12f}" for v in q)])


def read_poses_csv(path: Path) -> list[tuple[str, np.ndarray]]:
    """The rows of :func:`write_poses_csv` back as ``(image, T_base_tool0)``."""
    out = []
    with open(path, newline="") as fh:
        for row in csv.DictReader(fh):
            q = [float(row[k]) for k in ("qx", "qy", "qz", "qw")]
            t = [float(row[k]) for k in ("x_m", "y_m", "z_m")]
            out.append((row["image"], pose_matrix(Rotation.from_quat(q).as_matrix(), t)))
    return out


def write_intrinsics(
    path: Path, K: np.ndarray, dist: np.ndarray, size_wh: tuple[int, int], note: str
) -> None:
    """OpenCV FileStorage YAML with ``camera_matrix`` and ``distortion_coefficients``."""
    fs = cv2.FileStorage(str(path), cv2.FILE_STORAGE_WRITE)
    fs.write("image_width", int(size_wh[0]))
    fs.write("image_height", int(size_wh[1]))
    fs.write("camera_matrix", np.asarray(K, dtype=np.float64))
    fs.write("distortion_coefficients", np.asarray(dist, dtype=np.float64).reshape(1, -1))
    fs.writeComment(note)
    fs.release()


def read_intrinsics(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """``camera_matrix`` and ``distortion_coefficients`` of an OpenCV FileStorage file."""
    fs = cv2.FileStorage(str(path), cv2.FILE_STORAGE_READ)
    K, dist = fs.getNode("camera_matrix").mat(), fs.getNode("distortion_coefficients").mat()
    fs.release()
    if K is None or dist is None:
        raise DataSetError(f"{path}: no camera_matrix / distortion_coefficients")
    return K, dist.ravel()
