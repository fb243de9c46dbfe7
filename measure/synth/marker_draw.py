"""Drawing reference markers into a rendered image, through the real lens model.

Each marker is a small plane. Only its pixel box is evaluated: the box's rays come from a
coarse grid of exactly undistorted rays (:func:`measure.synth.optics.ray_grid`, bilinear
between nodes 8 px apart: within 2.2e-4 px of the exact rays on the standard head), each
pixel's coverage is integrated exactly
(:mod:`measure.synth.marker_pattern`), and the box is blurred by the optics PSF before it
replaces the image there. Within the box, each row is evaluated only where it comes within
``SPAN_MARGIN_PX`` of the label's projected outline (about half a box lies outside the label:
the kernel leaves those pixels as they are anyway, 20 % of its time). Noise and quantisation
are the caller's (the camera's) step.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from functools import lru_cache

import cv2
import numpy as np

from measure.calibration import StereoCalibration
from measure.markers.codes import apriltag_cells, ring_bits
from measure.markers.design import DEFAULT_DESIGN, MarkerDesign
from measure.synth.marker_pattern import APRILTAG, RING, marker_patch
from measure.synth.optics import ray_grid, vignetting
from measure.synth.targets import plate_homography

#: node spacing (px) of the ray grid a marker's box is interpolated from
RAY_STEP_PX = 8.0
#: reflectance of a marker's black label and white print
MARKER_BLACK, MARKER_WHITE = 0.06, 0.90


@dataclass(frozen=True)
class MarkerPatch:
    """One reference marker in a scene (LEFT camera optical frame, metres).

    ``normal``: unit normal out of the marker's face toward the cameras; ``up``: the in-plane
    direction of the code's origin (sector 0 of a ring, the tag's side; None: a fixed choice);
    ``diameter_m``: the white dot's diameter.
    """

    code: int
    center_m: np.ndarray
    normal: np.ndarray
    diameter_m: float
    up: np.ndarray | None = None
    design: MarkerDesign = field(default=DEFAULT_DESIGN)

    def __post_init__(self) -> None:
        if not 0 <= self.code < self.design.n_codes():
            raise ValueError(f"marker code {self.code} outside 0..{self.design.n_codes() - 1}")
        if not self.diameter_m > 0:
            raise ValueError(f"marker diameter_m must be positive, got {self.diameter_m}")


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``np.cross`` of two 3-vectors: the same arithmetic, without its overhead (a survey view
    asks for hundreds)."""
    a0, a1, a2 = float(a[0]), float(a[1]), float(a[2])
    b0, b1, b2 = float(b[0]), float(b[1]), float(b[2])
    return np.array([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0])


def marker_axes(normal: np.ndarray, up: np.ndarray | None) -> np.ndarray:
    """Columns ``(x, y, n)``: ``x`` along ``up`` (projected into the plane), ``y = n × x``;
    without ``up``, ``x`` is :func:`measure.markers.bias._plane_axes`' first axis."""
    n = np.asarray(normal, dtype=float).reshape(3)
    n = n / np.linalg.norm(n)
    if up is None:
        ref = np.array([1.0, 0.0, 0.0]) if abs(n[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
        x = _cross(n, ref)
        x /= np.linalg.norm(x)
    else:
        x = np.asarray(up, dtype=float).reshape(3)
        x = x - (x @ n) * n
        if np.linalg.norm(x) < 1e-9:
            raise ValueError("marker up must not be parallel to its normal")
        x = x / np.linalg.norm(x)
    return np.column_stack([x, _cross(n, x), n])


@lru_cache(maxsize=16)
def _outline_uv(d: MarkerDesign) -> np.ndarray:
    """Points (k, 2) around a design's printed label (dot diameters; read-only, cached)."""
    if d.kind == "ring":
        phi = np.linspace(0.0, 2 * np.pi, 48, endpoint=False)
        uv = d.label_radius * np.stack([np.cos(phi), np.sin(phi)], axis=1)
    else:
        x_lo, x_hi, y_lo, y_hi = d.label_box()
        s = np.linspace(0.0, 1.0, 9)
        xs, ys = x_lo + s * (x_hi - x_lo), y_lo + s * (y_hi - y_lo)
        uv = np.concatenate(
            [
                np.stack([xs, np.full_like(s, y_lo)], 1),
                np.stack([xs, np.full_like(s, y_hi)], 1),
                np.stack([np.full_like(s, x_lo), ys], 1),
                np.stack([np.full_like(s, x_hi), ys], 1),
            ]
        )
    uv.setflags(write=False)
    return uv


def _outline(m: MarkerPatch, R: np.ndarray, c: np.ndarray) -> np.ndarray:
    """Points (k, 3) around the printed marker (camera frame)."""
    return c + m.diameter_m * (_outline_uv(m.design) @ R[:, :2].T)


def _geometry(d: MarkerDesign, code: int) -> tuple[int, np.ndarray, np.ndarray, np.ndarray]:
    if d.kind == "ring":
        sectors = ring_bits(code, d.bits, d.min_distance).astype(np.float64)
        geo = np.array([d.ring_inner, d.ring_outer, d.label_radius])
        return RING, geo, sectors, np.zeros((1, 1))
    fld = np.ones((10, 10))
    fld[1:9, 1:9] = apriltag_cells(code)
    x0 = d.tag_offset - d.field_half
    geo = np.array([*d.label_box(), x0, d.field_half, d.tag_cell])
    return APRILTAG, geo, np.zeros(1), fld


#: a pixel this far (px) outside the label's projected outline is left as it is: the kernel
#: draws nothing a pixel or more outside the label; the outline's chords cut inside the curve
#: by under 0.3 px (48 points around a label under 300 px across)
SPAN_MARGIN_PX = 3


def _row_spans(outline_px: np.ndarray | None, w: int, h: int) -> np.ndarray:
    """Per row of a ``w`` × ``h`` box, the columns ``[lo, hi)`` within ``SPAN_MARGIN_PX`` of the
    label's outline polygon (box pixels); every column when the outline is None (its
    projection folded by the lens polynomial)."""
    spans = np.zeros((h, 2), dtype=np.int64)
    spans[:, 1] = w
    if outline_px is None:
        return spans
    m = SPAN_MARGIN_PX  # the mask reaches beyond the box: the outline may leave it
    mask = np.zeros((h + 2 * m, w + 2 * m), np.uint8)
    cv2.fillPoly(mask, [np.round((outline_px + m) * 16).astype(np.int32)], 1, cv2.LINE_8, 4)
    mask = cv2.dilate(mask, np.ones((2 * m + 1, 2 * m + 1), np.uint8))[m : m + h, m : m + w]
    rows = mask.any(axis=1)
    lo = np.argmax(mask, axis=1)
    hi = w - np.argmax(mask[:, ::-1], axis=1)
    spans[:, 0] = np.where(rows, lo, 0)
    spans[:, 1] = np.where(rows, hi, 0)
    return spans


def draw_marker(
    img: np.ndarray,
    stereo: StereoCalibration,
    side: str,
    m: MarkerPatch,
    R_cam: np.ndarray,
    t_cam: np.ndarray,
    blur_sigma_px: float,
    vignetting_strength: float,
    gain: float = 1.0,
) -> tuple[int, int, int, int] | None:
    """Draw marker ``m`` (its frame ``R_cam`` (columns x, y, n), centre ``t_cam``: camera
    ``side``'s frame) into ``img`` ((h, w) float32, fraction of full scale) with the optics
    blur. Returns the box ``(x, y, w, h)`` it replaced, None when out of view or seen from
    behind."""
    if float(R_cam[:, 2] @ t_cam) >= 0.0:
        return None  # the face looks away from this camera
    P = _outline(m, R_cam, t_cam)
    if np.any(P[:, 2] <= 1e-3):
        return None
    K, dist = (
        (stereo.K_left, stereo.dist_left) if side == "left" else (stereo.K_right, stereo.dist_right)
    )
    px = cv2.projectPoints(P, np.zeros(3), np.zeros(3), K, dist)[0].reshape(-1, 2)
    margin = math.ceil(3.0 * blur_sigma_px) + 3
    w_img, h_img = stereo.image_size
    # the lens polynomial folds points far outside the field back into the image: where the
    # pinhole image lies well outside, the outline point's pixel is the pinhole one
    pin = (P[:, :2] / P[:, 2:3]) @ np.asarray(K)[:2, :2].T + np.asarray(K)[:2, 2]
    far = ((pin[:, 0] < -0.1 * w_img) | (pin[:, 0] > 1.1 * w_img)
           | (pin[:, 1] < -0.1 * h_img) | (pin[:, 1] > 1.1 * h_img))  # fmt: skip
    px[far] = pin[far]
    x0, y0 = np.floor(px.min(axis=0)).astype(int) - 2 * margin
    x1, y1 = np.ceil(px.max(axis=0)).astype(int) + 2 * margin + 1
    x0, y0, x1, y1 = max(x0, 0), max(y0, 0), min(x1, w_img), min(y1, h_img)
    if x1 - x0 < 4 or y1 - y0 < 4:
        return None
    w, h = int(x1 - x0), int(y1 - y0)
    grid = ray_grid(stereo, side, x0, y0, w, h, RAY_STEP_PX)
    rays = np.stack([grid.nx, grid.ny])
    kind, geo, sectors, fld = _geometry(m.design, m.code)
    H = plate_homography(R_cam, t_cam, m.diameter_m)
    patch = img[y0:y1, x0:x1].astype(np.float32)
    lit = gain * vignetting(
        np.arange(x0, x1, dtype=np.float64)[None, :],
        np.arange(y0, y1, dtype=np.float64)[:, None],
        K,
        stereo.image_size,
        vignetting_strength,
    )
    levels = np.array([MARKER_BLACK, MARKER_WHITE])
    box = np.array([x0, y0], dtype=np.int64)
    spans = _row_spans(None if np.any(far) else px - [x0, y0], w, h)
    scene = (H, kind, geo, sectors, fld, levels, lit)
    marker_patch(rays, grid.x0, grid.y0, grid.step, box, *scene, patch, spans)
    if blur_sigma_px > 0:
        patch = cv2.GaussianBlur(patch, (0, 0), blur_sigma_px, borderType=cv2.BORDER_REPLICATE)
    # keep the box's outer margin as it was: the blur there saw the box's edge
    ix0 = margin if x0 > 0 else 0
    iy0 = margin if y0 > 0 else 0
    ix1 = w - margin if x1 < w_img else w
    iy1 = h - margin if y1 < h_img else h
    if ix1 <= ix0 or iy1 <= iy0:
        return None
    img[y0 + iy0 : y0 + iy1, x0 + ix0 : x0 + ix1] = patch[iy0:iy1, ix0:ix1]
    return (int(x0 + ix0), int(y0 + iy0), int(ix1 - ix0), int(iy1 - iy0))


def draw_markers(
    img: np.ndarray,
    stereo: StereoCalibration,
    side: str,
    markers: Sequence[MarkerPatch],
    blur_sigma_px: float,
    vignetting_strength: float,
    gain: float = 1.0,
) -> list[tuple[int, int, int, int]]:
    """Draw every marker (LEFT camera frame) into camera ``side``'s image ``img``; the boxes
    drawn."""
    boxes = []
    for m in markers:
        R = marker_axes(m.normal, m.up)
        c = np.asarray(m.center_m, dtype=float).reshape(3)
        if side == "right":
            R, c = stereo.R @ R, stereo.R @ c + np.asarray(stereo.T, dtype=float).reshape(3)
        box = draw_marker(img, stereo, side, m, R, c, blur_sigma_px, vignetting_strength, gain)
        if box is not None:
            boxes.append(box)
    return boxes
