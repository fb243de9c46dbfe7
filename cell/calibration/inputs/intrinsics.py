"""A mono camera's intrinsics from an OpenCV FileStorage file (YAML, XML or JSON).

Nodes: ``camera_matrix`` (3x3, px) and ``distortion_coefficients`` (4, 5, 8, 12 or 14 numbers,
OpenCV order), as OpenCV's calibration sample writes them; ``image_width`` and
``image_height`` (px) if present, else the images' size is taken.
"""

from __future__ import annotations

import re
from pathlib import Path

import cv2
import numpy as np

from cell.calibration.errors import CalibrationDataError
from cell.calibration.estimate.observations import Intrinsics


def _why(exc: BaseException) -> str:
    """``: the parser's words`` of an OpenCV FileStorage error (empty when it has none)."""
    text = str(exc.__cause__ or exc)
    m = re.search(r"in function '[^']*?: ([^']+)'", text)
    return f": {m.group(1)}" if m else " (empty or unreadable)"


def _matrix(fs: cv2.FileStorage, name: str, src: str) -> np.ndarray | None:
    """The matrix node ``name`` (None when absent); a node of another kind is refused."""
    node = fs.getNode(name)
    if node.empty() or node.isNone():
        return None
    if node.isSeq():  # a plain list of numbers
        try:
            return np.array([node.at(i).real() for i in range(node.size())], float)
        except cv2.error:
            raise CalibrationDataError(src, f"{name}: not a list of numbers") from None
    try:
        return node.mat()
    except cv2.error:
        raise CalibrationDataError(src, f"{name}: not an OpenCV matrix (!!opencv-matrix)") from None


def read_intrinsics(path: str | Path, image_size: tuple[int, int] | None = None) -> Intrinsics:
    """Read ``camera_matrix`` and ``distortion_coefficients``; refuse naming the node."""
    src = str(path)
    if Path(path).is_dir():
        raise CalibrationDataError(src, "is a directory, not an intrinsics file")
    if not Path(path).is_file():
        raise CalibrationDataError(src, "no such file")
    try:
        fs = cv2.FileStorage(src, cv2.FILE_STORAGE_READ)
    except (cv2.error, SystemError) as exc:  # an empty file: SystemError around cv2.error
        raise CalibrationDataError(src, f"not an OpenCV FileStorage file{_why(exc)}") from None
    if not fs.isOpened():
        raise CalibrationDataError(src, "not an OpenCV FileStorage file")
    try:
        if not fs.root().isMap():
            raise CalibrationDataError(src, "not a mapping of named nodes (camera_matrix, ...)")
        K = _matrix(fs, "camera_matrix", src)
        dist = _matrix(fs, "distortion_coefficients", src)
        w = fs.getNode("image_width")
        h = fs.getNode("image_height")
        size = (int(w.real()), int(h.real())) if not w.empty() and not h.empty() else image_size
    finally:
        fs.release()
    if K is None or np.shape(K) != (3, 3):
        raise CalibrationDataError(src, "camera_matrix: missing or not a 3x3 matrix")
    if not np.all(np.isfinite(K)) or K[0, 0] <= 0 or K[1, 1] <= 0 or abs(K[2, 2] - 1) > 1e-9:
        raise CalibrationDataError(src, f"camera_matrix: not a camera matrix: {K.tolist()}")
    if dist is None or np.size(dist) not in (4, 5, 8, 12, 14):
        raise CalibrationDataError(
            src, "distortion_coefficients: missing or not 4, 5, 8, 12 or 14 numbers"
        )
    dist = np.asarray(dist, float).reshape(-1)
    if not np.all(np.isfinite(dist)):
        raise CalibrationDataError(src, "distortion_coefficients: non-finite values")
    if size is None:
        raise CalibrationDataError(src, "image_width/image_height missing and no image to read")
    return Intrinsics(np.asarray(K, float), dist, (int(size[0]), int(size[1])))
