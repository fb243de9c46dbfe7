"""The opening of a through-hole seen against a lit background: background and wall crescent.

Looking through a bore of depth t at a view angle α to its axis, the lit background shows
through the intersection of the rim's ellipse with the bottom opening's, which the
projection moves by about t·tan α toward the camera's side of the hole. The bright region
is then a lens: on the camera's side it ends at the rim, on the far side at the *bottom*
edge of the far wall; between that edge and the far rim the wall itself is seen, a dark
crescent (at 30° of tilt and a 4 mm bore, a third of a ⌀10 mm opening). The two cameras
look at different angles and see different lenses (sizes 25 … 30 % apart), so the lens
is not the hole: the hole is the rim, the outline of lens *and* crescent.

:func:`with_wall_crescent` turns a bright candidate into that opening: on the search
image, the pixels brighter than the candidate's threshold or as far below the surface
level as it is above (the surface level: the median on circles one to one and a half
diameters out), the component around the candidate, filled, if it is disc-like. The
candidate keeps its threshold and gets ``surface_level``, which the full-resolution
outline (:func:`measure.edges.hole_region`) uses the same way.
"""

from __future__ import annotations

from dataclasses import replace

import cv2
import numpy as np

from measure.detect import SEARCH_SCALE, HoleCandidate
from measure.outline import disc_like

#: unit circle at 96 angles, and the three radii (× d) the surface level is read on
_COS_SIN = np.stack([np.cos(np.linspace(0.0, 2.0 * np.pi, 96, endpoint=False)),
                     np.sin(np.linspace(0.0, 2.0 * np.pi, 96, endpoint=False))])  # fmt: skip
_RADII = np.array([1.0, 1.25, 1.5])


def surface_level_search(small: np.ndarray, cx: float, cy: float, d: float) -> float:
    """Median of the search image (0 … 255) on circles 1.0, 1.25 and 1.5 × ``d`` from
    (``cx``, ``cy``) (search pixels): the surface beyond the hole."""
    rad = d * _RADII
    xs = np.rint(cx + np.outer(rad, _COS_SIN[0])).astype(int).ravel()
    ys = np.rint(cy + np.outer(rad, _COS_SIN[1])).astype(int).ravel()
    H, W = small.shape
    ok = (xs >= 0) & (ys >= 0) & (xs < W) & (ys < H)
    if not ok.any():
        return float(np.median(small))
    vals = small[ys[ok], xs[ok]]
    n = len(vals)
    k = n // 2
    if n % 2:
        return float(np.partition(vals, k)[k])
    part = np.partition(vals, [k - 1, k])
    return 0.5 * (float(part[k - 1]) + float(part[k]))  # as np.median


def with_wall_crescent(small: np.ndarray, cand: HoleCandidate) -> HoleCandidate:
    """A bright candidate grown by the bore wall's dark crescent beside it (full-res).

    ``small`` is the search image (every ``SEARCH_SCALE``-th pixel, 8 bit) the candidate
    was found in. Dark candidates and candidates cut by the border come back unchanged;
    bright ones get ``surface_level`` (fraction of full scale) and, when a crescent joins
    them into a larger disc-like region, that region's centroid, box and diameter.
    """
    if cand.polarity != "bright" or cand.touches_border:
        return cand
    s = SEARCH_SCALE
    cx, cy = (cand.centroid_px[0] - s // 2) / s, (cand.centroid_px[1] - s // 2) / s
    d = cand.diameter_px / s
    surf = surface_level_search(small, cx, cy, d)
    thr = cand.threshold * 255.0
    out = replace(cand, surface_level=surf / 255.0)
    if thr <= surf:
        return out
    img = cv2.medianBlur(small, 3)
    mask = ((img > thr) | (img < 2.0 * surf - thr)).astype(np.uint8)
    contours, _ = cv2.findContours(mask, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE)
    seed = (float(cx), float(cy))
    inside = [c for c in contours if cv2.pointPolygonTest(c, seed, False) >= 0]
    if not inside:
        return out
    c = max(inside, key=cv2.contourArea)
    area = cv2.contourArea(c)
    r0 = 0.5 * d
    if area < 1.05 * np.pi * r0 * r0 or area > 4.0 * np.pi * r0 * r0:
        return out  # nothing joined, or the region ran out into the surface
    x, y, w, h = cv2.boundingRect(c)
    H, W = small.shape
    if x == 0 or y == 0 or x + w == W or y + h == H:
        return out
    if not disc_like(c.reshape(-1, 2).astype(np.float64), (H, W), False):
        return out
    m = cv2.moments(c)
    return replace(
        out,
        centroid_px=(m["m10"] / m["m00"] * s + s // 2, m["m01"] / m["m00"] * s + s // 2),
        bbox=(x * s, y * s, w * s, h * s),
        diameter_px=float(2.0 * np.sqrt(m["m00"] / np.pi) * s),
    )
