"""Rendering stereo pairs of one hole with exact ground truth.

Cost control: the full frame gets a cheap background (surface texture and vignetting
interpolated from a 16-px grid, noise from a cached bank); only a window around the
hole's image is ray cast per pixel, and only pixels near an edge are supersampled
(``supersample``² samples each, i.e. area-integrated), then blurred by the optics PSF and
given fresh shot and read noise.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace

import cv2
import numpy as np

from measure.calibration import StereoCalibration
from measure.synth.hole_background import background as _background
from measure.synth.hole_scene import HoleGeometry, Shading, shade
from measure.synth.marker_draw import MarkerPatch, draw_markers
from measure.synth.optics import ray_grid, vignetting
from measure.synth.sensor import finish_region
from measure.synth.texture import TILE_CENTER_M, background_noise_at


@dataclass(frozen=True)
class RenderOptions:
    """How a hole pair is rendered. Levels are fractions of full scale.

    Attributes:
        bit_depth: 8 (uint8, 0..255) or 12 (uint16, 0..4095).
        read_noise_dn: read-noise σ in gray levels of the output bit depth.
        full_well_e: electrons at full scale for shot noise; ``None`` disables shot noise.
        blur_sigma_px: Gaussian optics PSF σ (pixels).
        supersample: samples per pixel side on edge pixels (area integration).
        surface, chamfer_level, wall, bottom: brightness of surface, chamfer, bore wall
            and through-hole.
        texture_amplitude: relative std of the surface albedo texture.
        vignetting: relative illumination loss at the image corner.
        chamfer_m: 45° chamfer size (metres); 0 for a sharp rim.
        hole_depth_m: bore depth (metres); ``None``: one diameter.
        highlight: peak brightness of a specular streak across the rim (0: none).
        occlusion_fraction: fraction of the rim circumference hidden by a burr flap (0..0.5).

    Realism (the "realistic" benchmark group; defaults leave the standard scene as is):
        lip_rounded: shade the ``chamfer_m`` cone as a rounded lip (soft edge; the truth is
            still the bore edge one ``chamfer_m`` below the surface).
        wall_light: directional light on the bore wall: brightness ×(1 ± wall_light) with
            azimuth, the side facing the light bright, the other in shadow.
        light_gradient: uneven light across the image: brightness ×(1 ± light_gradient)
            from one image edge to the other, direction seeded.
        object_fraction: a screw head inside the bore, a bright disc of this fraction of
            the bore radius, half a bore depth down (0: none); ``object_level`` its brightness.
        bayer: render through a BGGR colour filter (``colour_gains`` B, G, R) with noise on
            the mosaic and OpenCV's demosaicing; the images are then colour ``(h, w, 3)``.
        jpeg_quality: JPEG-compress the result (8-bit only; ``None``: none).
    """

    bit_depth: int = 8
    read_noise_dn: float = 2.0
    full_well_e: float | None = None
    blur_sigma_px: float = 0.7
    supersample: int = 5
    surface: float = 0.62
    chamfer_level: float = 0.36
    wall: float = 0.13
    bottom: float = 0.035
    texture_amplitude: float = 0.04
    vignetting: float = 0.25
    chamfer_m: float = 0.0
    hole_depth_m: float | None = None
    highlight: float = 0.0
    occlusion_fraction: float = 0.0
    lip_rounded: bool = False
    wall_light: float = 0.0
    light_gradient: float = 0.0
    object_fraction: float = 0.0
    object_level: float = 0.7
    bayer: bool = False
    colour_gains: tuple[float, float, float] = (0.75, 1.0, 0.85)
    jpeg_quality: int | None = None


@dataclass(frozen=True)
class HoleTruth:
    """Exact ground truth of a rendered hole, in the LEFT camera optical frame (metres).

    ``center_m``/``radius_m`` describe the hole at the surface; ``edge_center_m``/
    ``edge_radius_m`` the circle that forms the image edge (the bore edge, one chamfer
    depth below the surface; the same as the hole circle without chamfer). ``normal``
    points out of the material toward the camera. ``window_left``/``window_right`` are the
    ray-cast pixel windows ``(x, y, w, h)`` (empty if the hole is out of view).
    """

    center_m: np.ndarray
    normal: np.ndarray
    radius_m: float
    edge_center_m: np.ndarray
    edge_radius_m: float
    chamfer_m: float
    window_left: tuple[int, int, int, int]
    window_right: tuple[int, int, int, int]


@dataclass(frozen=True)
class StereoRender:
    """A rendered pair (``uint8`` or ``uint16`` images, shape (h, w), or (h, w, 3) BGR
    with ``bayer``) and its truth."""

    left: np.ndarray
    right: np.ndarray
    truth: HoleTruth


def _in_plane_axes(normal: np.ndarray, angle: float) -> tuple[np.ndarray, np.ndarray]:
    ref = np.array([1.0, 0.0, 0.0]) if abs(normal[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    a = np.cross(normal, ref)
    a /= np.linalg.norm(a)
    b = np.cross(normal, a)
    e1 = math.cos(angle) * a + math.sin(angle) * b
    return e1, np.cross(normal, e1)


def _window(
    stereo: StereoCalibration, side: str, geo: HoleGeometry, r_win: float
) -> tuple[int, int, int, int]:
    phi = np.linspace(0, 2 * np.pi, 72, endpoint=False)
    pts = geo.center + r_win * (np.outer(np.cos(phi), geo.e1) + np.outer(np.sin(phi), geo.e2))
    if np.any(pts[:, 2] <= 1e-3):
        return (0, 0, 0, 0)
    rvec = np.zeros(3)
    K, d = (
        (stereo.K_left, stereo.dist_left) if side == "left" else (stereo.K_right, stereo.dist_right)
    )
    px = cv2.projectPoints(pts, rvec, np.zeros(3), K, d)[0].reshape(-1, 2)
    w, h = stereo.image_size
    x0, y0 = np.floor(px.min(axis=0)).astype(int) - 4
    x1, y1 = np.ceil(px.max(axis=0)).astype(int) + 5
    x0, y0, x1, y1 = max(x0, 0), max(y0, 0), min(x1, w), min(y1, h)
    if x1 <= x0 or y1 <= y0:
        return (0, 0, 0, 0)
    return (int(x0), int(y0), int(x1 - x0), int(y1 - y0))


def _render_window(
    stereo: StereoCalibration,
    side: str,
    geo: HoleGeometry,
    sh: Shading,
    opts: RenderOptions,
    win: tuple[int, int, int, int],
) -> np.ndarray:
    """Area-integrated, vignetted, blurred window (fraction of full scale)."""
    x0, y0, w, h = win
    grid = ray_grid(stereo, side, x0 - 1, y0 - 1, w + 2, h + 2, 2.0)
    py, px = np.mgrid[y0 : y0 + h, x0 : x0 + w].astype(np.float64)
    nx, ny = grid.sample(px, py)
    val = shade(geo, sh, nx, ny)
    # supersample pixels near an edge (the rim, chamfer, burr) in plane-radius terms
    xp, yp = geo.plane_hit(nx, ny)
    rho = np.hypot(xp, yp)
    depth = float(np.linalg.norm(geo.center))
    f_px = (stereo.K_left if side == "left" else stereo.K_right)[0, 0]
    foot = depth / f_px / max(abs(geo.normal @ geo.center) / depth, 0.2)
    r, ch = geo.radius, geo.chamfer
    lo, hi = r - ch - 5 * foot, r + ch + 5 * foot
    if opts.occlusion_fraction > 0:
        lo, hi = lo - 0.14 * r, hi + 0.14 * r
    band = (rho > lo) & (rho < hi)
    if band.any():
        s = opts.supersample
        offs = (np.arange(s) + 0.5) / s - 0.5
        ox, oy = np.meshgrid(offs, offs)
        bx = (px[band][:, None] + ox.ravel()[None, :]).ravel()
        by = (py[band][:, None] + oy.ravel()[None, :]).ravel()
        snx, sny = grid.sample(bx, by)
        val[band] = shade(geo, sh, snx, sny).reshape(-1, s * s).mean(axis=1)
    K = stereo.K_left if side == "left" else stereo.K_right
    val *= vignetting(px, py, K, stereo.image_size, opts.vignetting)
    img = val.astype(np.float32)
    if opts.blur_sigma_px > 0:
        img = cv2.GaussianBlur(img, (0, 0), opts.blur_sigma_px, borderType=cv2.BORDER_REPLICATE)
    return img


def _finish(img: np.ndarray, opts: RenderOptions, win, rng: np.random.Generator) -> np.ndarray:
    """Scale to gray levels, add shot and read noise (fresh in the window), quantise. Read
    noise alone (the default) takes one compiled pass (:func:`finish_region`); ``img`` may be
    overwritten."""
    full = 255.0 if opts.bit_depth == 8 else 4095.0
    bank, by0, bx0, flipped = background_noise_at(img.shape, rng)
    x0, y0, w, h = win
    fresh = rng.standard_normal((h, w), dtype=np.float32) if w > 0 and h > 0 else None
    if not opts.full_well_e:
        read = np.float32(opts.read_noise_dn if opts.read_noise_dn > 0 else 0.0)
        out = np.empty(img.shape, dtype=np.uint8 if opts.bit_depth == 8 else np.uint16)
        fr = fresh if fresh is not None else np.zeros((0, 0), dtype=np.float32)
        finish_region(np.ascontiguousarray(img), np.float32(full), read, bank, by0, bx0,
                      flipped, fr, x0, y0, int(full), out)  # fmt: skip
        return out
    bank = bank[by0 : by0 + img.shape[0], bx0 : bx0 + img.shape[1]]
    bank = bank[::-1] if flipped else bank
    dn = img
    dn *= np.float32(full)
    gain = np.float32(full / opts.full_well_e)
    sigma = np.sqrt(np.float32(opts.read_noise_dn**2) + np.maximum(dn, 0) * gain)
    noise = sigma * bank
    if fresh is not None:
        noise[y0 : y0 + h, x0 : x0 + w] = sigma[y0 : y0 + h, x0 : x0 + w] * fresh
    dn += noise
    np.maximum(dn, 0.0, out=dn)
    if opts.bit_depth == 8:
        return cv2.convertScaleAbs(dn)  # rounds and saturates at 255
    np.minimum(dn, full, out=dn)
    return (dn + np.float32(0.5)).astype(np.uint16)


def _uneven(img: np.ndarray, strength: float, angle: float) -> None:
    """Multiply in place by a linear light ramp 1 ± ``strength`` across the image."""
    h, w = img.shape
    u = (np.arange(w, dtype=np.float32) - 0.5 * w) / (0.5 * w) * np.float32(math.cos(angle))
    v = (np.arange(h, dtype=np.float32) - 0.5 * h) / (0.5 * h) * np.float32(math.sin(angle))
    img *= 1.0 + np.float32(strength) * (v[:, None] + u[None, :])


def _mosaic(img: np.ndarray, gains: tuple[float, float, float]) -> np.ndarray:
    """A BGGR Bayer mosaic of a gray scene seen through colour gains (B, G, R)."""
    out = img * np.float32(gains[1])
    out[0::2, 0::2] = img[0::2, 0::2] * np.float32(gains[0])  # B
    out[1::2, 1::2] = img[1::2, 1::2] * np.float32(gains[2])  # R
    return out


def _camera_output(img: np.ndarray, opts: RenderOptions, win, rng) -> np.ndarray:
    """Noise and quantisation, then the optional demosaicing and JPEG compression."""
    if opts.bayer:
        raw = _finish(_mosaic(img, opts.colour_gains), opts, win, rng)
        out = cv2.cvtColor(raw, cv2.COLOR_BayerBG2BGR)
    else:
        out = _finish(img, opts, win, rng)
    if opts.jpeg_quality is not None:
        _, buf = cv2.imencode(".jpg", out, [cv2.IMWRITE_JPEG_QUALITY, int(opts.jpeg_quality)])
        out = cv2.imdecode(buf, cv2.IMREAD_UNCHANGED)
    return out


def _render_side(
    stereo, side, geo, sh, opts, rng, markers=()
) -> tuple[np.ndarray, tuple[int, int, int, int]]:
    img = _background(stereo, side, geo, sh, opts.vignetting)
    r_win = (1.75 if opts.highlight > 0 else 1.2) * geo.radius + 2.0 * geo.chamfer + 1e-3
    win = _window(stereo, side, geo, r_win)
    if win[2] > 0:
        margin = math.ceil(3 * opts.blur_sigma_px) + 1
        x0, y0, w, h = win
        big = (x0 - margin, y0 - margin, w + 2 * margin, h + 2 * margin)
        patch = _render_window(stereo, side, geo, sh, opts, big)
        img[y0 : y0 + h, x0 : x0 + w] = patch[margin : margin + h, margin : margin + w]
    if markers:  # labels stuck on the surface, drawn over it
        draw_markers(img, stereo, side, markers, opts.blur_sigma_px, opts.vignetting)
    if opts.light_gradient:
        _uneven(img, opts.light_gradient, sh.light_azimuth)
    return _camera_output(img, opts, win, rng), win


def _realism(opts: RenderOptions, r: float, depth: float, rng: np.random.Generator) -> dict:
    """Shading fields of the realism options (no random draws when all are off, so the
    standard scene's images stay the same for the same seed)."""
    if not (opts.wall_light or opts.light_gradient or opts.object_fraction or opts.lip_rounded):
        return {}
    return {
        "light_azimuth": float(rng.uniform(0, 2 * np.pi)),
        "wall_light": opts.wall_light,
        "object_radius": opts.object_fraction * r,
        "object_depth": 0.5 * depth,
        "object_level": opts.object_level,
        "lip_rounded": opts.lip_rounded,
    }


def render_hole_pair(
    stereo: StereoCalibration,
    center_m: np.ndarray,
    normal: np.ndarray,
    diameter_m: float,
    options: RenderOptions | None = None,
    seed: int = 0,
    markers: Sequence[MarkerPatch] = (),
) -> StereoRender:
    """Render the left and right images of one hole, with exact truth.

    Args:
        stereo: the stereo head (image size, intrinsics, distortion, extrinsics).
        center_m: hole centre at the surface, LEFT camera optical frame, metres (3,).
        normal: unit hole axis pointing out of the material toward the cameras (3,).
        diameter_m: bore diameter (metres).
        options: appearance and noise (:class:`RenderOptions`).
        seed: seeds texture placement, highlight/burr azimuth and noise.
        markers: reference markers in view (LEFT camera frame), drawn over the surface
            (:mod:`measure.synth.marker_draw`); none: the images are as without the argument.

    Returns:
        :class:`StereoRender` with ``uint8`` (8-bit) or ``uint16`` (12-bit) images. A hole
        (partly) outside the field of view is rendered as far as visible.
    """
    opts = options or RenderOptions()
    if opts.bit_depth not in (8, 12):
        raise ValueError(f"bit_depth must be 8 or 12, got {opts.bit_depth}")
    if opts.jpeg_quality is not None and opts.bit_depth != 8:
        raise ValueError("jpeg_quality needs bit_depth 8")
    c = np.asarray(center_m, dtype=float).reshape(3)
    n = np.asarray(normal, dtype=float).reshape(3)
    n = n / np.linalg.norm(n)
    if n @ c > 0:
        raise ValueError("normal must point toward the camera (normal · center < 0)")
    rng = np.random.default_rng(seed)
    e1, e2 = _in_plane_axes(n, float(rng.uniform(0, 2 * np.pi)))
    r = 0.5 * float(diameter_m)
    depth = opts.hole_depth_m if opts.hole_depth_m is not None else 2 * r
    geo = HoleGeometry(
        center=c, normal=n, e1=e1, e2=e2, radius=r, chamfer=opts.chamfer_m, depth=depth
    )
    sh = Shading(
        surface=opts.surface,
        chamfer=opts.chamfer_level,
        wall=opts.wall,
        bottom=opts.bottom,
        burr=0.85 * opts.surface,
        texture_amplitude=opts.texture_amplitude,
        highlight=opts.highlight,
        highlight_azimuth=float(rng.uniform(0, 2 * np.pi)),
        occlusion_fraction=opts.occlusion_fraction,
        occlusion_azimuth=float(rng.uniform(0, 2 * np.pi)),
        texture_offset=(
            TILE_CENTER_M + float(rng.uniform(-5e-3, 5e-3)),
            TILE_CENTER_M + float(rng.uniform(-5e-3, 5e-3)),
        ),
        **_realism(opts, r, depth, rng),
    )
    left, win_l = _render_side(stereo, "left", geo, sh, opts, rng, markers)
    geo_r = geo.transformed(stereo.R, stereo.T)
    right, win_r = _render_side(stereo, "right", geo_r, sh, opts, rng, markers)
    truth = HoleTruth(
        center_m=c.copy(),
        normal=n.copy(),
        radius_m=r,
        edge_center_m=c - opts.chamfer_m * n,
        edge_radius_m=r,
        chamfer_m=opts.chamfer_m,
        window_left=win_l,
        window_right=win_r,
    )
    return StereoRender(left=left, right=right, truth=truth)


def render_reference_pair(
    stereo: StereoCalibration,
    center_m: np.ndarray,
    normal: np.ndarray,
    diameter_m: float = 0.010,
    options: RenderOptions | None = None,
    seed: int = 0,
    markers: Sequence[MarkerPatch] = (),
) -> StereoRender:
    """Render a reference target: a precision bore (sharp rim, fine texture) in a gauge plate.

    Same frames, units and return value as :func:`render_hole_pair`; the cell's thermal
    identification measures such targets.
    """
    base = options or RenderOptions()
    opts = replace(
        base, chamfer_m=0.0, highlight=0.0, occlusion_fraction=0.0, texture_amplitude=0.015
    )
    return render_hole_pair(stereo, center_m, normal, diameter_m, opts, seed, markers)
