"""Calibration plate targets: geometry and detection (chessboard, asymmetric circle grid)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np

from measure.target_grid import grid_problem

TARGET_KINDS = ("chessboard", "circles")


@dataclass(frozen=True)
class TargetSpec:
    """A plate target.

    ``chessboard``: ``cols`` × ``rows`` inner corners, square side ``pitch_m``.
    ``circles``: OpenCV's asymmetric grid, ``cols`` × ``rows`` circles; row ``i`` holds
    circles at x = (2j + i mod 2)·pitch, y = i·pitch (metres).
    """

    kind: str
    cols: int
    rows: int
    pitch_m: float
    circle_diameter_frac: float = 0.7

    def __post_init__(self) -> None:
        if self.kind not in TARGET_KINDS:
            raise ValueError(f"target kind must be one of {TARGET_KINDS}, got {self.kind!r}")
        if self.cols < 3 or self.rows < 3 or not self.pitch_m > 0:
            raise ValueError(f"bad target size {self.cols}x{self.rows}, pitch {self.pitch_m} m")

    @property
    def pattern_size(self) -> tuple[int, int]:
        """``(cols, rows)`` as OpenCV's detectors take it."""
        return (self.cols, self.rows)

    def object_points(self) -> np.ndarray:
        """Feature positions on the plate (N, 3, metres, z = 0), in detector order."""
        s = self.pitch_m
        if self.kind == "chessboard":
            jj, ii = np.meshgrid(np.arange(self.cols), np.arange(self.rows))
            pts = np.stack([jj.ravel() * s, ii.ravel() * s], axis=1)
        else:
            pts = np.array(
                [[(2 * j + i % 2) * s, i * s] for i in range(self.rows) for j in range(self.cols)],
                dtype=float,
            )
        return np.concatenate([pts, np.zeros((len(pts), 1))], axis=1)

    def plate_bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """Plate corners (x, y) min and max (metres): the pattern plus a margin."""
        p = self.object_points()[:, :2]
        m = 1.5 * self.pitch_m
        return p.min(axis=0) - m, p.max(axis=0) + m


#: chessboard detectors, tried in this order until one finds the board: OpenCV's classic
#: detector with its fast pre-check (cheap rejection of images without a board), the classic
#: detector without it (the pre-check rejects some real boards: uneven light, boards near the
#: image border), and the sector-based detector ``findChessboardCornersSB`` (exhaustive).
CHESSBOARD_DETECTORS = ("fast", "plain", "sb")

_CLASSIC = cv2.CALIB_CB_ADAPTIVE_THRESH | cv2.CALIB_CB_NORMALIZE_IMAGE
_SB = cv2.CALIB_CB_NORMALIZE_IMAGE | cv2.CALIB_CB_EXHAUSTIVE | cv2.CALIB_CB_ACCURACY


@dataclass(frozen=True)
class TargetDetection:
    """The outcome of :func:`find_target` on one image.

    Attributes:
        points: feature positions (N, 2, pixels) in :meth:`TargetSpec.object_points` order,
            or ``None``.
        reason: why not found ("" when found).
        detector: which detector found it (``"fast"``, ``"plain"``, ``"sb"`` for chessboards,
            ``"grid"`` or ``"clustering"`` for circle grids; "" when none did).
    """

    points: np.ndarray | None
    reason: str
    detector: str = ""


def to_gray8(gray: np.ndarray) -> np.ndarray:
    """An 8-bit single-channel copy for OpenCV's detectors (8-bit kept, others rescaled)."""
    return (
        gray
        if gray.dtype == np.uint8
        else cv2.normalize(gray, None, 0, 255, cv2.NORM_MINMAX).astype(np.uint8)
    )


def detect_target(gray: np.ndarray, spec: TargetSpec) -> tuple[np.ndarray | None, str]:
    """Find the target's features (N, 2, pixels) or say why not (see :func:`find_target`).

    Returns ``(points, "")`` or ``(None, reason)`` where reason is "target not found",
    "too few corners (k of n)" or "too blurred (edge width w px)".
    """
    det = find_target(gray, spec)
    return det.points, det.reason


#: the widest edge (10-90 % rise, px) of a target image accepted by default
MAX_EDGE_WIDTH_PX = 4.0


def find_target(
    gray: np.ndarray, spec: TargetSpec, max_edge_width_px: float = MAX_EDGE_WIDTH_PX
) -> TargetDetection:
    """Find the target with each detector in turn (:data:`CHESSBOARD_DETECTORS`), then check
    the corner count, that the corners form the board's grid (:mod:`measure.target_grid`: a
    board size given wrong) and the sharpness of the image (edges up to
    ``max_edge_width_px``)."""
    img = to_gray8(gray)
    n = spec.cols * spec.rows
    if spec.kind == "chessboard":
        pts, detector = _find_chessboard(img, spec.pattern_size)
    else:
        pts, detector = _find_circles(img, spec.pattern_size)
    if pts is None:
        return TargetDetection(None, "target not found")
    if len(pts) < n:
        return TargetDetection(None, f"too few corners ({len(pts)} of {n})", detector)
    pts = pts.reshape(-1, 2).astype(np.float32)
    grid = spec.object_points()[:, :2] / spec.pitch_m
    wrong = grid_problem(img, pts, grid, spec.cols, spec.rows, spec.kind == "chessboard")
    if wrong:
        return TargetDetection(None, f"not a {spec.cols} x {spec.rows} board: {wrong}", detector)
    if spec.kind == "chessboard":
        width = float(cv2.estimateChessboardSharpness(img, spec.pattern_size, pts)[0][0])
    else:
        width = _edge_width(img, pts)
    if width > max_edge_width_px:
        return TargetDetection(None, f"too blurred (edge width {width:.1f} px)", detector)
    return TargetDetection(pts.astype(np.float64), "", detector)


#: chessboards are searched on a copy scaled to at most this many pixels on the longest side
#: (5-megapixel images cost OpenCV's detectors seconds, a minute when there is no board), then
#: the corners are refined at full resolution
DETECT_MAX_SIDE_PX = 1280


def detection_copy(img: np.ndarray) -> tuple[np.ndarray, float]:
    """``img`` shrunk by the smallest whole factor that brings it to at most
    :data:`DETECT_MAX_SIDE_PX` (INTER_AREA: the mean of each factor x factor block, OpenCV's
    fast path; a 5 MP image in 2 ms instead of 8), and the scale (1 / factor)."""
    factor = math.ceil(max(img.shape[:2]) / DETECT_MAX_SIDE_PX)
    if factor <= 1:
        return img, 1.0
    h, w = img.shape[:2]
    return cv2.resize(img, (w // factor, h // factor), interpolation=cv2.INTER_AREA), 1.0 / factor


def _find_chessboard(img: np.ndarray, size: tuple[int, int]) -> tuple[np.ndarray | None, str]:
    crit = (cv2.TERM_CRITERIA_EPS | cv2.TERM_CRITERIA_COUNT, 50, 1e-4)
    small, scale = detection_copy(img)

    def full_res(pts: np.ndarray) -> np.ndarray:
        # pixel centres: x_full + 0.5 = (x_small + 0.5) / scale
        return ((pts.astype(np.float32) + 0.5) / scale - 0.5).astype(np.float32)

    for detector, flags in (("fast", _CLASSIC | cv2.CALIB_CB_FAST_CHECK), ("plain", _CLASSIC)):
        found, pts = cv2.findChessboardCorners(small, size, flags=flags)
        if found and pts is not None:
            return cv2.cornerSubPix(img, full_res(pts), (5, 5), (-1, -1), crit), detector
    found, pts = cv2.findChessboardCornersSB(small, size, flags=_SB)
    if found and pts is not None:
        if scale == 1.0:  # already sub-pixel (CALIB_CB_ACCURACY)
            return pts, "sb"
        return cv2.cornerSubPix(img, full_res(pts), (5, 5), (-1, -1), crit), "sb"
    return None, ""


def _find_circles(img: np.ndarray, size: tuple[int, int]) -> tuple[np.ndarray | None, str]:
    asym = cv2.CALIB_CB_ASYMMETRIC_GRID
    for detector, flags in (("grid", asym), ("clustering", asym | cv2.CALIB_CB_CLUSTERING)):
        found, pts = cv2.findCirclesGrid(img, size, flags=flags)
        if found and pts is not None:
            return pts, detector
    return None, ""


def _edge_width(img: np.ndarray, pts: np.ndarray) -> float:
    """Edge width (10–90 % rise, px) from the gradient over the target's bounding box."""
    x0, y0 = np.floor(pts.min(axis=0)).astype(int)
    x1, y1 = np.ceil(pts.max(axis=0)).astype(int)
    roi = img[max(y0, 0) : y1 + 1, max(x0, 0) : x1 + 1].astype(np.float32)
    if roi.size < 16:
        return 0.0
    g = cv2.magnitude(cv2.Sobel(roi, cv2.CV_32F, 1, 0), cv2.Sobel(roi, cv2.CV_32F, 0, 1)) / 8.0
    contrast = float(np.percentile(roi, 95) - np.percentile(roi, 5))
    peak = float(np.percentile(g, 99.5))
    return 0.8 * contrast / max(peak, 1e-6)
