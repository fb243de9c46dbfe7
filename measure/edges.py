"""Canny edges and sub-pixel edge points around the hole region of one image.

Two sub-pixel methods:

- ``"parabola"`` (default): Devernay's sub-pixel Canny — a parabola through the gradient
  magnitude (Sobel of a Gaussian-smoothed image) at the edge pixel and its two neighbours
  along the dominant gradient axis; the vertex is the edge point.
- ``"linear"``: the published method — linear (first-order Lagrange) interpolation of the raw
  gray values across the edge, at the level midway between the gray values 3 px inside and
  3 px outside.

Only Canny pixels within a few pixels of the hole region's outline are used, so texture,
chamfer rings and the bore's bottom edge do not enter.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import cv2
import numpy as np

from measure.detect import HoleCandidate
from measure.edge_kernels import (
    binary_moments,
    parabola_points,
    ring_histogram,
    scaled_int16,
)
from measure.masks import above, below, grow_box, ring_bounds, ring_mask
from measure.outline import without_bites
from measure.slope import slope_shift

EDGE_METHODS = ("parabola", "linear")


@dataclass(frozen=True)
class HoleRegion:
    """The hole region in a region of interest; coordinates are full-image pixels.

    ``inside_level`` / ``outside_level`` are the median gray levels (fractions of full
    scale) just inside the outline and in a ring just outside it; ``threshold`` the level
    midway between them that drew the outline; ``ring_level`` the median in a wider ring
    5 … 20 % of the diameter outside the outline (a grommet or washer shows there).
    """

    roi: tuple[int, int, int, int]
    centroid_px: tuple[float, float]
    area_px: float
    mask: np.ndarray  # bool, ROI-sized
    threshold: float = 0.0
    inside_level: float = 0.0
    outside_level: float = 0.0
    ring_level: float = 0.0
    box: tuple[int, int, int, int] | None = None  # the mask's bounding box, ROI pixels


@dataclass(frozen=True)
class EdgePoints:
    """Sub-pixel edge points (N, 2) in full-image pixels and their gradient strength.

    ``width_px`` is, per point, the width of a Gaussian through the three gradient samples
    across the edge (projected onto the gradient; inf where undefined); ``blur_sigma_px``
    its median, the edge's total blur (optics, smoothing and the Sobel kernel).
    """

    points_px: np.ndarray
    strength: np.ndarray
    blur_sigma_px: float = 0.0
    width_px: np.ndarray | None = None


def _median(img: np.ndarray, mask: np.ndarray, full: float) -> float | None:
    """Median gray level (fraction of full scale) of the masked pixels (a nonzero ``uint8``
    or bool mask), from a histogram; ``None`` when no pixel is masked."""
    bins = 256 if img.dtype == np.uint8 else 1024
    hist = cv2.calcHist([img], [0], mask.view(np.uint8), [bins], [0, full + 1]).ravel()
    return _hist_median(hist, bins, full)


def _ring_median(img: np.ndarray, dist: np.ndarray, inner: float, outer: float, full: float):
    """:func:`_median` of the pixels ``inner`` (exclusive) … ``outer`` px outside the
    region (:func:`measure.masks.ring_mask` of its distance map ``dist``); for 8-bit
    images one compiled pass (:func:`measure.edge_kernels.ring_histogram`)."""
    if img.dtype != np.uint8:
        return _median(img, ring_mask(dist, inner, outer), full)
    lo, hi = ring_bounds(inner, outer)
    return _hist_median(ring_histogram(img, dist, lo, hi).astype(np.float32), 256, full)


def _hist_median(hist: np.ndarray, bins: int, full: float) -> float | None:
    """The median's gray level (fraction of full scale) from float32 histogram counts."""
    cdf = np.cumsum(hist)
    if cdf[-1] <= 0:
        return None
    k = int(np.searchsorted(cdf, 0.5 * cdf[-1]))
    return (k + 0.5) * (full + 1) / bins / full


Box = tuple[int, int, int, int]


def _region(mask: np.ndarray, seed: tuple[float, float]) -> tuple[np.ndarray, Box | None]:
    """The filled outer outline of the mask component around ``seed`` (ROI pixels), and
    its bounding box (x, y, w, h; ``None`` when there is no component).

    Islands inside the hole (a screw) do not matter; a bite into the outline (a screw
    head touching the rim in the image) is bridged by the ellipse through the rest.
    """
    contours, _ = cv2.findContours(mask.view(np.uint8), cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE)
    inside = [c for c in contours if cv2.pointPolygonTest(c, seed, False) >= 0]
    pool = inside or list(contours)
    region = np.zeros(mask.shape, np.uint8)
    if not pool:
        return region, None
    c = max(pool, key=cv2.contourArea)
    cv2.drawContours(region, [c], -1, 1, thickness=cv2.FILLED)
    box = cv2.boundingRect(c)
    area = cv2.contourArea(c)
    hull_area = cv2.contourArea(cv2.convexHull(c))
    if len(c) >= 24 and area < 0.97 * hull_area:
        rest = without_bites(c)
        if rest is not None and len(rest) >= 12:
            ell = cv2.fitEllipse(rest.astype(np.float32))
            if np.all(np.isfinite(ell[1])) and min(ell[1]) > 2:
                cv2.ellipse(region, ell, 1, thickness=cv2.FILLED)
                box = cv2.boundingRect(region)
    return region, box


def _count(mask: np.ndarray, box: tuple[int, int, int, int] | None) -> float:
    """Set pixels of ``mask``, all of which lie in ``box`` (x, y, w, h)."""
    if box is None:
        return 0.0
    x, y, w, h = box
    return float(cv2.countNonZero(mask[y : y + h, x : x + w]))


def hole_region(
    img: np.ndarray, full: float, cand: HoleCandidate, margin_px: int = 10
) -> HoleRegion:
    """Crop around the candidate and find its region at full resolution; centroid by moments.

    The candidate's threshold gives a first outline; the gray levels just inside it and
    in a ring 3 … 3 + max(4, 3 % of the diameter) px outside it set a local threshold
    midway between the two, which draws the final outline. So the outline follows the
    rim where the light is uneven, and lies on the middle of a soft edge. For a bright
    interior (a through-hole against a lit background) pixels as far *below* the
    surrounding level are part of the hole too: the bore wall, seen at a tilt as a dark
    crescent between the background and the rim. Masks, erosion, the inner ring and the
    moments are worked out on the region's box (plus what they reach), not the whole crop.
    """
    H, W = img.shape
    x, y, w, h = cand.bbox
    m = margin_px + int(0.12 * max(w, h))
    x0, y0 = max(x - m, 0), max(y - m, 0)
    x1, y1 = min(x + w + m, W), min(y + h + m, H)
    roi_img = img[y0:y1, x0:x1]
    cx, cy = cand.centroid_px
    seed = (float(cx - x0), float(cy - y0))
    box = (x0, y0, x1 - x0, y1 - y0)
    dark = cand.polarity == "dark"
    level = cand.threshold
    surf = cand.surface_level
    if dark:
        first = below(roi_img, level * full)
    elif surf is None or level <= surf:
        first = above(roi_img, level * full)
    else:  # the lit background and the wall crescent beside it (measure.opening)
        first = above(roi_img, level * full) | (roi_img < (2 * surf - level) * full)
    region, rbox = _region(first, seed)
    inside = outside = level
    dist = None
    if rbox is not None:
        k = max(4, int(0.03 * cand.diameter_px))
        ker = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (7, 7))
        cys, cxs, _, _ = grow_box(rbox, 3, region.shape)  # the kernel's reach: zeros round it
        core = cv2.erode(region[cys, cxs], ker)  # (zero outside that box)
        dist = cv2.distanceTransform(cv2.compare(region, 0, cv2.CMP_EQ), cv2.DIST_L2, 3)
        ys, xs, _, _ = grow_box(rbox, 5 + 2 * k, region.shape)  # holds the ring 3 … 3 + k px
        lout = _ring_median(roi_img[ys, xs], dist[ys, xs], 3, 3 + k, full)
        if not dark and lout is not None:  # the lit part only, not the wall crescent
            core &= above(roi_img[cys, cxs], lout * full)
        lin = _median(roi_img[cys, cxs], core, full)
        if lin is not None and lout is not None and (lin < lout) == dark:
            inside, outside = lin, lout
            level = 0.5 * (lin + lout)
            if dark:
                mask = below(roi_img, level * full)
            else:  # a lit background: the bore wall seen at a tilt is a dark crescent
                mask = above(roi_img, level * full) | (roi_img < (2 * lout - level) * full)
            refined, fbox = _region(mask, seed)
            ratio = _count(refined, fbox) / _count(region, rbox)
            # the same region, better placed; else keep the first (moved by a pixel or two:
            # the first distance map serves)
            if 0.6 < ratio < 1.6:
                region, rbox = refined, fbox
    mask = region.view(bool)  # 0/1
    if rbox is None:
        return HoleRegion(box, (cx, cy), 0.0, mask, level, inside, outside, outside)
    bx, by = rbox[:2]
    m00, m10, m01 = binary_moments(region[by : by + rbox[3], bx : bx + rbox[2]])
    if m00 <= 0:
        return HoleRegion(box, (cx, cy), 0.0, mask, level, inside, outside, outside, rbox)
    centroid = (m10 / m00 + bx + x0, m01 / m00 + by + y0)
    d = 2.0 * np.sqrt(m00 / np.pi)
    if dist is None:
        dist = cv2.distanceTransform(cv2.compare(region, 0, cv2.CMP_EQ), cv2.DIST_L2, 3)
    wide = _ring_median(roi_img, dist, 0.05 * d, 0.2 * d, full)
    return HoleRegion(
        box,
        centroid,
        m00,
        mask,
        level,
        inside,
        outside,
        outside if wide is None else wide,
        rbox,
    )


def _percentile(a: np.ndarray, q: float) -> float:
    """``np.percentile(a, q)`` (linear interpolation; equal to NumPy's to the last bit of
    ``a``'s precision) from one partial sort, without NumPy's generic bookkeeping; ``a``
    is 1-D and not empty."""
    n = len(a)
    pos = q / 100.0 * (n - 1)
    lo = int(np.floor(pos))
    hi = min(lo + 1, n - 1)
    part = np.partition(a, [lo, hi] if hi > lo else [lo])
    b0, b1, t = float(part[lo]), float(part[hi]), pos - lo
    d = b1 - b0
    return float(a.dtype.type(b1 - d * (1.0 - t) if t >= 0.5 else b0 + d * t))


def _band(region: np.ndarray, half_width: int) -> np.ndarray:
    """:func:`outline_band` as a 0/1 ``uint8`` mask."""
    u8 = region.view(np.uint8)
    k = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (2 * half_width + 1, 2 * half_width + 1))
    return cv2.subtract(cv2.dilate(u8, k), cv2.erode(u8, k))


def outline_band(region: np.ndarray, half_width: int) -> np.ndarray:
    """Pixels within ``half_width`` of the region outline."""
    u8 = region.astype(np.uint8)
    k = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (2 * half_width + 1, 2 * half_width + 1))
    return cv2.dilate(u8, k) > cv2.erode(u8, k)


@lru_cache(maxsize=16)
def gradient_kernels(sigma_px: float, full: float) -> tuple[np.ndarray, np.ndarray]:
    """Separable kernels (derivative, smoothing) of Sobel ∘ Gaussian, scaled by 1/``full``.

    ``cv2.sepFilter2D(img, CV_32F, d, s)`` is then ``Sobel_x(GaussianBlur(img / full, σ))``
    in one pass on the raw image (``(s, d)``: the y derivative): the Gaussian of
    ``cv2.GaussianBlur`` for a float image (``getGaussianKernel`` of size round(8σ + 1) | 1)
    convolved with Sobel's [−1, 0, 1] and [1, 2, 1]. Equal to the two passes up to
    rounding, away from the border.
    """
    if sigma_px > 0:
        k = round(sigma_px * 8 + 1) | 1
        g = cv2.getGaussianKernel(k, sigma_px, cv2.CV_32F).ravel().astype(np.float64)
    else:
        g = np.ones(1)
    d = np.convolve(g, [-1.0, 0.0, 1.0]) / full
    sm = np.convolve(g, [1.0, 2.0, 1.0])
    return d.astype(np.float32), sm.astype(np.float32)


#: pixels the edge step reads beyond the band: kernel reach (3), the parabola's neighbour
#: and the linear method's ±3 px, with one to spare
_CROP_MARGIN_PX = 7


def _edge_crop(box, shape, band_px: int) -> tuple[int, int, int, int]:
    """(x0, y0, x1, y1) of the ROI part the edge step needs: the outline band and its
    reach, from the region's box (x, y, w, h) in the ROI of ``shape`` (h, w)."""
    bx, by, bw, bh = box
    m = band_px + _CROP_MARGIN_PX
    H, W = shape
    return max(bx - m, 0), max(by - m, 0), min(bx + bw + m, W), min(by + bh + m, H)


def subpixel_edges(
    img: np.ndarray,
    full: float,
    region: HoleRegion,
    method: str = "parabola",
    sigma_px: float = 1.0,
    slope_correction: bool = False,
) -> EdgePoints:
    """Canny edge pixels near the hole outline, refined to sub-pixel points.

    Only the part of the ROI around the outline band is filtered (the region's box plus
    the filters' reach), and smoothing and gradient are one separable pass each
    (:func:`gradient_kernels`). With ``slope_correction`` (``"parabola"`` only) each
    gradient maximum is moved back by the shift a brightness slope beside the edge
    causes (:mod:`measure.slope`).
    """
    if method not in EDGE_METHODS:
        raise ValueError(f"edge method must be one of {EDGE_METHODS}, got {method!r}")
    if region.box is None:
        return EdgePoints(np.zeros((0, 2)), np.zeros(0))
    rx, ry = region.roi[:2]
    cx0, cy0, cx1, cy1 = _edge_crop(region.box, region.mask.shape, 3)
    x0, y0, w, h = rx + cx0, ry + cy0, cx1 - cx0, cy1 - cy0
    sub = img[y0 : y0 + h, x0 : x0 + w]
    kd, ks = gradient_kernels(float(sigma_px), float(full))
    gx = cv2.sepFilter2D(sub, cv2.CV_32F, kd, ks)
    gy = cv2.sepFilter2D(sub, cv2.CV_32F, ks, kd)
    mag = cv2.magnitude(gx, gy)
    band = _band(region.mask[cy0:cy1, cx0:cx1], 3)  # 0/1
    vals = mag[band.view(bool)]
    if len(vals) == 0:
        return EdgePoints(np.zeros((0, 2)), np.zeros(0))
    peak = _percentile(vals, 98.0)
    if peak <= 0:
        return EdgePoints(np.zeros((0, 2)), np.zeros(0))
    scale = np.float32(16000.0 / max(float(mag.max()), 1e-12))  # |g| ≤ max: no clipping
    dx, dy = scaled_int16(gx, gy, scale)
    hi = 0.35 * peak * float(scale)
    edges = cv2.Canny(dx, dy, 0.5 * hi, hi, L2gradient=True)
    found = cv2.findNonZero(cv2.bitwise_and(edges, band))  # row by row, as np.nonzero
    if found is None:
        return EdgePoints(np.zeros((0, 2)), np.zeros(0))
    found = found.reshape(-1, 2).astype(np.intp)
    xs, ys = found[:, 0], found[:, 1]
    keep = (xs >= 3) & (ys >= 3) & (xs < w - 3) & (ys < h - 3)
    xs, ys = xs[keep], ys[keep]
    if method == "parabola":
        pts, strength, _, _, widths, normals = parabola_points(xs, ys, gx, gy, mag)
    else:
        pts, strength, widths = _linear_points(sub, full, gx, gy, mag, xs, ys)
    finite = widths[np.isfinite(widths)]
    blur = _percentile(finite, 50.0) if len(finite) else 0.0
    if slope_correction and method == "parabola" and len(pts):
        centre = (region.centroid_px[0] - x0, region.centroid_px[1] - y0)
        shift = slope_shift(gx, gy, pts, normals, strength, blur, centre)
        pts -= shift[:, None] * normals
    return EdgePoints(
        points_px=pts + np.array([x0, y0], dtype=np.float64),
        strength=strength,
        blur_sigma_px=blur,
        width_px=widths,
    )


def _linear_points(sub, full, gx, gy, mag, xs, ys):
    """The linear method's points (M, 2), and per point the gradient magnitude and the
    edge width (as :func:`measure.edge_kernels.parabola_points` gives them)."""
    gxs, gys = gx[ys, xs], gy[ys, xs]
    horiz = np.abs(gxs) >= np.abs(gys)
    sx, sy = horiz.astype(np.intp), (~horiz).astype(np.intp)
    # the gradient magnitude at each pixel and its two neighbours along the dominant axis
    g0 = mag[ys, xs].astype(np.float64)
    gm = mag[ys - sy, xs - sx].astype(np.float64)
    gp = mag[ys + sy, xs + sx].astype(np.float64)
    raw = sub.astype(np.float32) * np.float32(1.0 / full)
    off, ok = _linear(raw, gx, gy, xs, ys, sx, sy)
    pts = np.stack([xs + off * sx, ys + off * sy], axis=1)[ok].astype(np.float64)
    gxs, gys, strength = gxs[ok], gys[ok], g0[ok]
    return pts, strength, _edge_widths(gm[ok], strength, gp[ok], gxs, gys, horiz[ok])


def _edge_widths(gm, g0, gp, gxs, gys, horiz) -> np.ndarray:
    """Gaussian width (px) of the gradient profile across the edge at each point (inf: none),
    from the magnitudes before, at and after it along the dominant axis (float64) and the
    gradient there (float32)."""
    lg0 = np.log(np.maximum(g0, 1e-12))
    curv = np.log(np.maximum(gm, 1e-12)) - 2.0 * lg0 + np.log(np.maximum(gp, 1e-12))
    g = np.maximum(np.hypot(gxs, gys).astype(np.float64), 1e-12)
    along = np.where(horiz, np.abs(gxs), np.abs(gys)) / g
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(curv < 0, np.sqrt(-1.0 / curv) * along, np.inf)


def _linear(raw, gx, gy, xs, ys, sx, sy) -> tuple[np.ndarray, np.ndarray]:
    """Mid-level crossing of the raw gray values, linearly interpolated between pixels."""
    ks = np.arange(-3, 4)
    vals = np.stack([raw[ys + k * sy, xs + k * sx] for k in ks], axis=1).astype(np.float64)
    level = 0.5 * (vals[:, 0] + vals[:, -1])
    diff = vals - level[:, None]
    off = np.zeros(len(xs))
    best = np.full(len(xs), np.inf)
    for j in range(len(ks) - 1):
        a, b = diff[:, j], diff[:, j + 1]
        cross = (a * b <= 0) & (a != b)
        with np.errstate(divide="ignore", invalid="ignore"):
            pos = ks[j] + a / (a - b)
        better = cross & (np.abs(pos) < best)
        off = np.where(better, pos, off)
        best = np.where(better, np.abs(pos), best)
    ok = best <= 1.0
    return off, ok
