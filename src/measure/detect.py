"""Finding the hole in one image: exposure checks and disc-like region candidates.

The search runs on every 4th pixel of each row and column (well under a ms for 5 MP): a
threshold midway between the darkest pixels and the median, connected components of the
dark (or, failing that, bright) class, and a disc test: an ellipse fitted to the region's
outline must follow most of it closely. Regions cut by the border are kept and flagged, so
the caller can say so instead of "no hole".
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from measure.errors import ImageError

#: downsampling factor of the search image
SEARCH_SCALE = 4


@dataclass(frozen=True)
class HoleCandidate:
    """A disc-like region in full-resolution pixel coordinates.

    ``threshold`` separates hole from surface (gray level as a fraction of full scale),
    ``polarity`` is ``"dark"`` (hole darker than the surface) or ``"bright"``.
    """

    centroid_px: tuple[float, float]
    bbox: tuple[int, int, int, int]
    diameter_px: float
    polarity: str
    threshold: float
    touches_border: bool


def full_scale(img: np.ndarray) -> float:
    """Full-scale gray level: 255 for uint8; 4095 for 12-bit data in uint16, else 65535."""
    if img.dtype == np.uint8:
        return 255.0
    return 4095.0 if int(img.max()) <= 4095 else 65535.0


def check_image(img: np.ndarray, which: str) -> float:
    """Reject unusable images (type, shape, saturated, black, flat); return the full scale."""
    if not isinstance(img, np.ndarray) or img.ndim != 2:
        shape = getattr(img, "shape", None)
        raise ImageError(which, f"must be a single-channel 2-D array, got shape {shape}")
    if img.dtype not in (np.uint8, np.uint16):
        raise ImageError(which, f"must be uint8 or uint16, got {img.dtype}")
    if min(img.shape) < 16:
        raise ImageError(which, f"too small ({img.shape[1]}x{img.shape[0]} px)")
    full = full_scale(img)
    sub = img[::8, ::8]
    saturated = float(np.mean(sub >= full - 1))
    if saturated > 0.5:
        raise ImageError(which, f"saturated: {saturated:.0%} of the pixels are at full scale")
    p99 = float(np.percentile(sub, 99))
    if p99 < 0.04 * full:
        raise ImageError(which, f"black: 99 % of the pixels are below {p99:.0f} of {full:.0f}")
    p1 = float(np.percentile(sub, 1))
    if p99 - p1 < 0.05 * full:
        raise ImageError(which, f"no contrast: gray levels span only {p1:.0f}..{p99:.0f}")
    return full


def _to_search_image(img: np.ndarray, full: float) -> np.ndarray:
    """Every 4th pixel in each direction (0.2 ms for 5 MP); the hole is a large blob."""
    o = SEARCH_SCALE // 2
    small = img[o::SEARCH_SCALE, o::SEARCH_SCALE]
    if small.dtype != np.uint8:
        small = np.clip(small.astype(np.float32) * (255.0 / full), 0, 255).astype(np.uint8)
    return np.ascontiguousarray(small)


def _disc_like(mask: np.ndarray, x: int, y: int, w: int, h: int, border: bool) -> bool:
    """Does the region's outline (away from the image border) follow an ellipse?"""
    crop = np.pad(mask[y : y + h, x : x + w], 1).astype(np.uint8)
    contours, _ = cv2.findContours(crop, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE)
    if not contours:
        return False
    pts = max(contours, key=len).reshape(-1, 2).astype(np.float64) - 1.0 + (x, y)
    if border:
        H, W = mask.shape
        keep = (pts[:, 0] > 0) & (pts[:, 1] > 0) & (pts[:, 0] < W - 1) & (pts[:, 1] < H - 1)
        pts = pts[keep]
    if len(pts) < 12:
        return False
    (cx, cy), (a2, b2), ang = cv2.fitEllipse(pts.astype(np.float32))
    if min(a2, b2) <= 2 or min(a2, b2) / max(a2, b2) < 0.35:
        return False
    t = np.deg2rad(ang)
    d = pts - (cx, cy)
    u = d[:, 0] * np.cos(t) + d[:, 1] * np.sin(t)
    v = -d[:, 0] * np.sin(t) + d[:, 1] * np.cos(t)
    rel = np.abs(np.hypot(u / (a2 / 2), v / (b2 / 2)) - 1.0)
    tol = max(0.06, 1.5 / (0.5 * min(a2, b2)))
    return float(np.median(rel)) < tol / 2 and float(np.mean(rel < tol)) > 0.6


def find_candidates(
    img: np.ndarray,
    full: float,
    roi: tuple[int, int, int, int] | None = None,
    min_diameter_px: float = 12.0,
) -> list[HoleCandidate]:
    """Disc-like dark regions (else bright ones) in ``img`` (optionally within ``roi``)."""
    ox, oy = 0, 0
    if roi is not None:
        ox, oy, rw, rh = roi
        img = img[oy : oy + rh, ox : ox + rw]
    small = _to_search_image(img, full)
    p_lo, p_med, p_hi = np.percentile(small[::2, ::2], (0.1, 50.0, 99.9))
    H, W = small.shape
    s = SEARCH_SCALE
    for polarity in ("dark", "bright"):
        if polarity == "dark":
            if p_med - p_lo < 0.12 * 255:
                continue
            thr = 0.5 * (p_lo + p_med)
            mask = small <= thr
        else:
            if p_hi - p_med < 0.12 * 255:
                continue
            thr = 0.5 * (p_hi + p_med)
            mask = small > thr
        n, labels, stats, cents = cv2.connectedComponentsWithStats(
            mask.astype(np.uint8), connectivity=8
        )
        found: list[HoleCandidate] = []
        for i in range(1, n):
            x, y, w, h, area = (int(v) for v in stats[i])
            d_px = 2.0 * np.sqrt(area / np.pi) * s
            if d_px < min_diameter_px or area > 0.5 * H * W:
                continue
            border = x == 0 or y == 0 or x + w == W or y + h == H
            if not _disc_like(labels == i, x, y, w, h, border):
                continue
            found.append(
                HoleCandidate(
                    centroid_px=(
                        float(cents[i][0] * s + s // 2 + ox),
                        float(cents[i][1] * s + s // 2 + oy),
                    ),
                    bbox=(x * s + ox, y * s + oy, w * s, h * s),
                    diameter_px=float(d_px),
                    polarity=polarity,
                    threshold=float(thr) / 255.0,
                    touches_border=border,
                )
            )
        if found:
            return found
    return []
