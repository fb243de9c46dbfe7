"""Rendering stereo pairs of a flat calibration plate (chessboard or asymmetric circle grid).

The plate is a plane, so each pixel's ray meets it at a homography of the pixel's undistorted
ray (cached per camera: :mod:`measure.synth.pixel_rays`). Only the plate's bounding box in
the image is evaluated; each pixel's reflectance is the exact area integral across the
pattern's edges (:mod:`measure.synth.target_pattern`), the limit of many supersamples.
Then, as before: vignetting (20 % at the image corner), a Gaussian optics blur and Gaussian
read noise, quantised to 8 bits. :mod:`measure.synth.target_reference` keeps the old
point-sampling renderer as the reference.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np

from measure.calibration import StereoCalibration
from measure.synth.lru import Lru
from measure.synth.pixel_rays import pixel_rays, pixel_rays_key
from measure.synth.sensor import quantize_u8
from measure.synth.target_pattern import CHESSBOARD, CIRCLES, plate_image, plate_region
from measure.target import TargetSpec

#: relative illumination lost at the image corner
VIGNETTING = 0.2
#: pixels added around the plate's projected outline (its edges bow between the samples)
BOX_MARGIN_PX = 4


@dataclass(frozen=True)
class TargetRender:
    """A plate pair (uint8) and its pose ``T_left_plate`` (4×4, metres)."""

    left: np.ndarray
    right: np.ndarray
    T_left_plate: np.ndarray


def _camera(stereo: StereoCalibration, side: str) -> tuple[np.ndarray, np.ndarray]:
    if side == "left":
        return stereo.K_left, stereo.dist_left
    return stereo.K_right, stereo.dist_right


def plate_box(
    stereo: StereoCalibration, side: str, R: np.ndarray, t: np.ndarray, spec: TargetSpec
) -> tuple[int, int, int, int] | None:
    """Pixel box ``(x0, y0, x1, y1)`` (exclusive end) holding the plate's image in camera
    ``side`` (plate at ``R``, ``t`` in that camera's frame); the whole image when part of
    the plate lies behind the camera; None when it is out of view."""
    w, h = stereo.image_size
    lo, hi = spec.plate_bounds()
    s = np.linspace(0.0, 1.0, 65)
    xs, ys = lo[0] + s * (hi[0] - lo[0]), lo[1] + s * (hi[1] - lo[1])
    outline = np.concatenate(
        [
            np.stack([xs, np.full_like(s, lo[1])], 1),
            np.stack([xs, np.full_like(s, hi[1])], 1),
            np.stack([np.full_like(s, lo[0]), ys], 1),
            np.stack([np.full_like(s, hi[0]), ys], 1),
        ]
    )
    P = outline @ R[:, :2].T + t
    if np.any(P[:, 2] <= 1e-3):
        return (0, 0, w, h)
    K, d = _camera(stereo, side)
    px = cv2.projectPoints(P, np.zeros(3), np.zeros(3), K, d)[0].reshape(-1, 2)
    x0, y0 = np.floor(px.min(axis=0)).astype(int) - BOX_MARGIN_PX
    x1, y1 = np.ceil(px.max(axis=0)).astype(int) + BOX_MARGIN_PX + 1
    x0, y0, x1, y1 = max(x0, 0), max(y0, 0), min(x1, w), min(y1, h)
    if x1 - x0 < 3 or y1 - y0 < 3:
        return None
    return int(x0), int(y0), int(x1), int(y1)


def plate_homography(R: np.ndarray, t: np.ndarray, pitch_m: float) -> np.ndarray:
    """``H`` (3, 3): a ray ``d = (x/z, y/z, 1)`` of the camera meets the plate ``z = 0`` (at
    ``R``, ``t`` in the camera frame) at ``(H[0] . d, H[1] . d) / H[2] . d`` pitches, in front
    of the camera where ``H[2] . d > 0``."""
    r1, r2, r3 = R[:, 0], R[:, 1], R[:, 2]
    a = float(r3 @ t)  # x_plate = [a (r1 . d) - (r1 . t)(r3 . d)] / (r3 . d), depth a / (r3 . d)
    sign = 1.0 if a > 0 else -1.0
    return sign * np.stack(
        [(a * r1 - (r1 @ t) * r3) / pitch_m, (a * r2 - (r2 @ t) * r3) / pitch_m, r3]
    )


def _light(stereo: StereoCalibration, side: str, vignetting: float, gain: float) -> np.ndarray:
    """:func:`plate_region`'s ``light``: (gain, strength, cx, cy, r_corner²)."""
    w, h = stereo.image_size
    K = _camera(stereo, side)[0]
    cx, cy = float(K[0, 2]), float(K[1, 2])
    rc2 = max(cx, w - 1 - cx) ** 2 + max(cy, h - 1 - cy) ** 2
    return np.array([gain, vignetting, cx, cy, rc2])


def _plate_args(stereo, side, R, t, spec, vignetting, gain, blur=None):
    """The arguments of :func:`plate_region` but the region and the output; the rays are
    valid over the whole image, or (``blur`` given) over the rows :func:`_region` asks for."""
    light = _light(stereo, side, vignetting, gain)
    box = plate_box(stereo, side, R, t, spec) or (0, 0, 0, 0)
    rows = None
    if blur is not None:
        w, h = stereo.image_size
        (_, y0, _, y1), _ = _region(box, blur, w, h)
        rows = (y0 - 1, y1 + 1) if box[2] > box[0] and box[3] > box[1] else (0, 0)
    nx, ny = pixel_rays(stereo, side, rows)
    lo, hi = spec.plate_bounds()
    bounds = np.array([lo[0], hi[0], lo[1], hi[1]]) / spec.pitch_m
    kind = CHESSBOARD if spec.kind == "chessboard" else CIRCLES
    H = plate_homography(R, t, spec.pitch_m)
    return (nx, ny, np.array(box, dtype=np.int64), H, kind, float(spec.cols), float(spec.rows),
            0.5 * spec.circle_diameter_frac, bounds, light)  # fmt: skip


def render_plate(
    stereo: StereoCalibration,
    side: str,
    R: np.ndarray,
    t: np.ndarray,
    spec: TargetSpec,
    vignetting: float = 0.0,
    gain: float = 1.0,
) -> np.ndarray:
    """The plate (at ``R``, ``t`` in camera ``side``'s frame) as that camera sees it before the
    optics blur: area-integrated reflectance times ``gain (1 - vignetting (r / r_corner)²)``
    ((h, w) float32)."""
    w, h = stereo.image_size
    out = np.empty((h, w), dtype=np.float32)
    plate_image(*_plate_args(stereo, side, R, t, spec, vignetting, gain), out)
    return out


#: a region's blurred pixels equal the whole frame's (bit for bit) this far inside it beyond
#: the Gaussian's reach (OpenCV's taps reach ceil(4 sigma) px, 3 at sigma 0.7; measured: 8 px
#: suffice there, 4-6 do not, the filter's border rows take another path) when the region's
#: left column is aligned to ALIGN_PX (the rows' SIMD blocks then match the frame's)
BLUR_MARGIN_PX, ALIGN_PX = 8, 64
#: how many (camera, light, blur) surrounds are kept (20 MB each at 5 MP)
CACHE_SURROUNDS = 4

_surrounds = Lru(CACHE_SURROUNDS)


def _surround(stereo: StereoCalibration, side: str, blur: float) -> np.ndarray:
    """The frame with no plate in view, lit and blurred ((h, w) float32, read-only; cached):
    what every pixel far from the plate shows."""
    key = (pixel_rays_key(stereo, side), VIGNETTING, 255.0, float(blur))
    hit = _surrounds.lookup(key)
    if hit is not None:
        return hit
    w, h = stereo.image_size
    nx = np.zeros((1, 1), dtype=np.float32)  # no plate pixel: only the light matters, no ray
    nx.setflags(write=False)
    none = np.zeros(4, dtype=np.int64)
    img = np.empty((h, w), dtype=np.float32)
    plate_image(nx, nx, none, np.eye(3), CHESSBOARD, 1.0, 1.0, 0.5, np.zeros(4),
                _light(stereo, side, VIGNETTING, 255.0), img)  # fmt: skip
    if blur > 0:
        img = cv2.GaussianBlur(img, (0, 0), blur)
    img.setflags(write=False)
    return _surrounds.keep(key, img)


def _region(box, blur: float, w: int, h: int) -> tuple[tuple[int, int, int, int], tuple]:
    """The pixels to render around ``box`` (x0, y0, x1, y1) and, inside them, the ones whose
    blurred values are the whole frame's (as (x0, y0, x1, y1) of the frame)."""
    m = BLUR_MARGIN_PX + math.ceil(4.0 * blur) if blur > 0 else 0
    x0, y0 = max(box[0] - 2 * m, 0) // ALIGN_PX * ALIGN_PX, max(box[1] - 2 * m, 0)
    x1, y1 = min(box[2] + 2 * m, w), min(box[3] + 2 * m, h)
    inner = (x0 + m if x0 > 0 else 0, y0 + m if y0 > 0 else 0,
             x1 - m if x1 < w else w, y1 - m if y1 < h else h)  # fmt: skip
    return (x0, y0, x1, y1), inner


def _render_side(stereo, side, R, t, spec, blur, noise, rng) -> np.ndarray:
    """One camera's image: the plate drawn and blurred over its box only (the rest of the frame
    is the cached blurred surround: the same pixels as blurring the whole frame), read noise
    over the whole frame (OpenCV's generator, 5x numpy's speed at 5 MP, seeded per image from
    ``rng``), quantised to 8 bits."""
    w, h = stereo.image_size
    args = _plate_args(stereo, side, R, t, spec, VIGNETTING, 255.0, blur)
    base = _surround(stereo, side, blur)
    dn = np.empty((0, 0), dtype=np.float32)
    if noise > 0:
        cv2.setRNGSeed(int(rng.integers(0, 2**31 - 1)))
        dn = np.empty((h, w), dtype=np.float32)
        cv2.randn(dn, 0.0, float(noise))
    out = np.empty((h, w), dtype=np.uint8)
    quantize_u8(base, dn, 0, 0, out)
    box = args[2]
    if box[2] > box[0] and box[3] > box[1]:
        (x0, y0, x1, y1), (ix0, iy0, ix1, iy1) = _region(box, blur, w, h)
        img = np.empty((y1 - y0, x1 - x0), dtype=np.float32)
        plate_region(*args[:2], np.array([x0, y0, x1, y1], dtype=np.int64), *args[2:], img)
        if blur > 0:
            img = cv2.GaussianBlur(img, (0, 0), blur)
        inner = np.ascontiguousarray(img[iy0 - y0 : iy1 - y0, ix0 - x0 : ix1 - x0])
        quantize_u8(inner, dn, ix0, iy0, out)
    return out


def render_target_pair(
    stereo: StereoCalibration,
    spec: TargetSpec,
    T_left_plate: np.ndarray,
    blur_sigma_px: float = 0.7,
    noise_dn: float = 2.0,
    supersample: int | None = None,
    seed: int = 0,
) -> TargetRender:
    """Render a calibration plate at ``T_left_plate`` (plate frame: pattern in z = 0).

    Each pixel integrates the pattern over its area exactly, so ``supersample`` (the sample
    count per pixel side of the old point-sampling renderer) changes nothing; it is accepted
    for old callers only. About 0.2 s of CPU per view of a 5-megapixel head, after the first
    view of a head (which computes its rays: a few seconds).
    """
    del supersample  # the area integral is exact: no samples to choose
    rng = np.random.default_rng(seed)
    T = np.asarray(T_left_plate, dtype=float)
    left = _render_side(stereo, "left", T[:3, :3], T[:3, 3], spec, blur_sigma_px, noise_dn, rng)
    T_right = np.eye(4)
    T_right[:3, :3], T_right[:3, 3] = stereo.R, stereo.T
    Tr = T_right @ T
    right = _render_side(stereo, "right", Tr[:3, :3], Tr[:3, 3], spec, blur_sigma_px, noise_dn, rng)
    return TargetRender(left=left, right=right, T_left_plate=T)
