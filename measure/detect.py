"""Finding the hole in one image: input checks and disc-like region candidates.

The search runs on every 4th pixel of each row and column (a few ms for 5 MP) and is a
*threshold ladder*: the dark class is thresholded at five levels between the darkest
pixels and the median (25 % … 85 % of the way), each level's outer contours are tested
for being disc-like (an ellipse fitted to the outline must follow most of it closely),
and the discs found at several levels are grouped by position and size. Within a group
the hole is the longest *plateau* — consecutive levels giving the same diameter within
4 % — and of equal plateaus the darker one: a sharp rim gives the same region over a
wide range of levels, while a chamfer ring, a shadow or a soft lip joins the region only
at some levels. A small disc inside a larger one (a dark fragment of a screw or its
shadow inside the bore) belongs to the larger one and is dropped. Discs that show at
two or more levels come first (a shadow or a stain next to the hole, or texture near the
surface level, shows at one level only): dark ones, else bright ones (a through-hole
against a lit background), and only if there are none, one-level discs. A dark disc
inside a bright one is a bore inside a grommet when the two are concentric (the bright
one goes), the bore wall's crescent beside a lit background when not (the dark one goes).
Regions cut by the border are kept and flagged, so the caller can say so instead of
"no hole".

Input types and exposure checks are in :mod:`measure.image_input`, the outline tests (disc-like,
bites) in :mod:`measure.outline`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np

from measure.image_input import (
    SEARCH_SCALE,
    check_image,
    full_scale,
    quantiles_u8,
    to_gray,
    to_search_image,
)
from measure.outline import disc_like, outline_prefilter, without_bites

__all__ = [
    "SEARCH_SCALE",
    "HoleCandidate",
    "check_image",
    "find_candidates",
    "full_scale",
    "quantiles_u8",
    "to_gray",
    "to_search_image",
    "without_bites",
]
#: fractions of the way from the darkest pixels to the median at which the ladder thresholds
LADDER = (0.25, 0.4, 0.55, 0.7, 0.85)
#: relative diameter change that still counts as "the same region" between ladder levels
PLATEAU_TOLERANCE = 0.04


@dataclass(frozen=True)
class HoleCandidate:
    """A disc-like region in full-resolution pixel coordinates.

    ``threshold`` separates hole from surface (gray level as a fraction of full scale),
    ``polarity`` is ``"dark"`` (hole darker than the surface) or ``"bright"``;
    ``levels`` is how many ladder levels gave this region (its plateau length);
    ``alternates`` the same hole's regions at the other levels (another run of levels),
    which the left/right cross-check may prefer when their sizes agree better;
    ``surface_level`` the surface's gray level around a bright hole (fraction of full
    scale; set by :func:`measure.opening.with_wall_crescent`, ``None`` otherwise).
    """

    centroid_px: tuple[float, float]
    bbox: tuple[int, int, int, int]
    diameter_px: float
    polarity: str
    threshold: float
    touches_border: bool
    levels: int = 1
    alternates: tuple[HoleCandidate, ...] = ()
    surface_level: float | None = None


def _levels(quantiles: tuple[float, float, float]):
    """(polarity, [thresholds 0..255], extreme level) for the dark class, then the bright,
    from the search image's 0.1 %, 50 % and 99.9 % quantiles."""
    p_lo, p_med, p_hi = quantiles
    if p_med - p_lo >= 0.2 * 255:
        yield "dark", [p_lo + f * (p_med - p_lo) for f in LADDER], p_lo
    if p_hi - p_med >= 0.2 * 255:
        yield "bright", [p_hi - f * (p_hi - p_med) for f in LADDER], p_hi


def _discs(
    mask: np.ndarray,
    min_area: float,
    level: int,
    border_only: bool,
    reach,
    tally: list[int] | None = None,
    shape: tuple[int, int] | None = None,
    offset: tuple[int, int] = (0, 0),
) -> list[tuple]:
    """Disc-like outer regions of a mask: (cx, cy, area, bbox, border, level) in search px.

    ``mask`` may be a window of the search image's mask at ``offset`` (x, y) holding all
    its set pixels, with ``shape`` the whole image's: the outlines are the same.

    Outlines shorter than the smallest disc's perimeter, or filling their box far less
    than an ellipse does (π/4), are passed over before the disc test. Regions touching
    the border are tested only with ``border_only`` (then only they are). ``reach(x, y,
    w, h)`` tells how far past the threshold a box reaches (0: not at all, 1: to the
    image's extreme): a region must reach 0.5 — a hole's interior goes far past the
    threshold that outlines it, a texture speck or a shadow barely crosses it.
    """
    H, W = mask.shape if shape is None else shape
    contours, _ = cv2.findContours(
        mask.view(np.uint8), cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE, offset=offset
    )
    min_len = max(8, int(2.0 * math.sqrt(math.pi * min_area)))  # 2√(π A): a disc's perimeter
    out = []
    sel = [c for c in contours if len(c) >= min_len]
    if not sel:
        return out
    lengths = np.fromiter(map(len, sel), dtype=np.intp, count=len(sel))
    starts = np.cumsum(lengths) - lengths
    pts = (np.concatenate(sel) if len(sel) > 1 else sel[0]).reshape(-1, 2)
    ok, boxes, borders = outline_prefilter(pts, starts, (H, W), float(min_area), border_only)
    for j in np.flatnonzero(ok):
        c = sel[j]
        x, y, w, h = (int(v) for v in boxes[j])
        border = bool(borders[j])
        if reach(x, y, w, h) < 0.5:
            continue
        if tally is not None:
            tally[0] += 1
        if disc_like(c.reshape(-1, 2), (H, W), border):
            m = cv2.moments(c)
            area = m["m00"]
            out.append((m["m10"] / area, m["m01"] / area, area, (x, y, w, h), border, level))
            continue
        rest = None if border else without_bites(c)
        if rest is not None and disc_like(rest, (H, W), False):  # the rim around a bite
            (ex, ey), (a2, b2), _ = cv2.fitEllipse(rest.astype(np.float32))
            out.append((ex, ey, 0.25 * np.pi * a2 * b2, (x, y, w, h), False, level))
    return out


def _plateau(members: list[tuple]) -> tuple:
    """The member in the middle of the longest run of levels with the same diameter (the
    darkest run at most one level shorter, since a chamfer ring joins the bore at the
    higher levels; when all runs are single levels, the largest region: the rim around a
    patchy interior), plus the run length and the other runs' middles."""
    members = sorted(members, key=lambda m: m[5])
    runs: list[list[tuple]] = [[members[0]]]
    for m in members[1:]:
        prev = runs[-1][-1]
        same = abs(np.sqrt(m[2] / prev[2]) - 1.0) <= PLATEAU_TOLERANCE and m[5] == prev[5] + 1
        if same:
            runs[-1].append(m)
        else:
            runs.append([m])
    longest = max(len(r) for r in runs)
    if longest == 1:
        best = max(runs, key=lambda r: r[0][2])
    else:  # the darkest run nearly as long: a chamfer ring joins the bore at higher levels
        best = next(r for r in runs if len(r) >= longest - 1 and len(r) >= 2)
    others = tuple(r[len(r) // 2] for r in runs if r is not best)
    return best[len(best) // 2] + (len(best), others)


def _group(discs: list[tuple]) -> list[tuple]:
    """Group discs found at several levels into holes; drop discs inside a larger hole.

    Returns (cx, cy, area, bbox, border, level, plateau length, other levels' discs,
    number of levels the hole shows at) per hole.
    """
    groups: list[list[tuple]] = []
    for d in sorted(discs, key=lambda d: -d[2]):
        r = np.sqrt(d[2] / np.pi)
        for g in groups:
            g0 = g[0]
            r0 = np.sqrt(g0[2] / np.pi)
            if np.hypot(d[0] - g0[0], d[1] - g0[1]) < 0.25 * r0 and r > 0.6 * r0:
                g.append(d)
                break
        else:
            groups.append([d])
    picks = [(*_plateau(g), len({m[5] for m in g})) for g in groups]
    if len(picks) < 2:
        return picks
    xy = np.array([(p[0], p[1]) for p in picks])
    area = np.array([p[2] for p in picks])
    n_lev = np.array([p[8] for p in picks])
    dist = np.hypot(xy[:, None, 0] - xy[None, :, 0], xy[:, None, 1] - xy[None, :, 1])
    # p (row) lies inside a larger disc q (column) that holds over at least as many levels
    inside = (
        (area[None, :] > area[:, None])
        & (n_lev[None, :] >= n_lev[:, None])
        & (dist < np.sqrt(area / np.pi)[None, :])
    )
    return [p for p, nested in zip(picks, inside.any(axis=1), strict=True) if not nested]


def _threshold(img: np.ndarray, thr: float, below: bool) -> np.ndarray:
    """``img <= thr`` (``below``) or ``img > thr`` as a 0/1 ``uint8`` mask of a ``uint8``
    image: one ``cv2.threshold`` at ⌊thr⌋ (for integer pixels the same test), several times
    faster than NumPy's comparison with a float."""
    kind = cv2.THRESH_BINARY_INV if below else cv2.THRESH_BINARY
    return cv2.threshold(img, math.floor(thr), 1, kind)[1]


def _reach(small: np.ndarray, polarity: str, thr: float, extreme: float):
    """``reach(x, y, w, h)`` for :func:`_discs`: how far past ``thr`` toward ``extreme``
    the darkest (bright class: brightest) pixel of the box goes (0 … 1)."""
    span = max(abs(thr - extreme), 1.0)

    def reach(x: int, y: int, w: int, h: int) -> float:
        box = small[y : y + h, x : x + w]
        if polarity == "dark":
            return (thr - float(box.min())) / span
        return (float(box.max()) - thr) / span

    return reach


def _cross_polarity(found: dict[str, tuple[list, list]]) -> None:
    """Settle dark discs lying inside bright ones (in place).

    Concentric (centres within 15 % of the bright radius): a dark bore inside a bright
    grommet or washer — the bright disc goes. Off-centre: the dark crescent of the bore
    wall beside a lit background seen through the hole — the dark disc goes.
    """
    if "dark" not in found or "bright" not in found:
        return
    dark, bright = found["dark"][1], found["bright"][1]
    drop_dark, drop_bright = set(), set()
    for i, d in enumerate(dark):
        for j, b in enumerate(bright):
            rb = np.sqrt(b[2] / np.pi)
            off = np.hypot(d[0] - b[0], d[1] - b[1])
            if d[2] >= b[2] or off >= rb:
                continue
            if off < 0.15 * rb:
                drop_bright.add(j)
            else:
                drop_dark.add(i)
    found["dark"][1][:] = [d for i, d in enumerate(dark) if i not in drop_dark]
    found["bright"][1][:] = [b for j, b in enumerate(bright) if j not in drop_bright]


def find_candidates(
    small: np.ndarray,
    roi: tuple[int, int, int, int] | None = None,
    min_diameter_px: float = 16.0,
    stats: dict | None = None,
    others: list[HoleCandidate] | None = None,
) -> list[HoleCandidate]:
    """Disc-like dark regions (else bright ones) in the search image (optionally in ``roi``).

    ``small`` is the search image of :func:`check_image`; ``roi`` and the returned
    coordinates are full-resolution pixels. ``stats``, when given, receives what decided:
    ``contrast`` per class (fraction of full scale from the extreme to the median; a class
    is searched from 0.2) and ``regions`` (compact regions that got the disc test).
    ``others``, when given, receives the other polarity's holes that hold over two or
    more levels (the left/right check's fallback when the returned ones find no partner).
    """
    ox, oy = 0, 0
    s = SEARCH_SCALE
    if roi is not None:
        x, y, w, h = (int(v) for v in roi)
        x0, y0 = max(x, 0) // s, max(y, 0) // s
        small = small[y0 : max((y + h) // s, y0), x0 : max((x + w) // s, x0)]
        ox, oy = x0 * s, y0 * s
        if min(small.shape) < 4:
            return []
    min_area = np.pi * (0.5 * min_diameter_px / s) ** 2
    small = cv2.medianBlur(small, 3)  # texture and noise specks would each be an outline
    found = {}
    tally = [0]
    p_lo, p_med, p_hi = quantiles_u8(small, (0.001, 0.5, 0.999))
    if stats is not None:
        stats["contrast"] = {"dark": (p_med - p_lo) / 255.0, "bright": (p_hi - p_med) / 255.0}
    for border_only in (False, True):  # regions cut by the border only when nothing else
        for polarity, thresholds, extreme in _levels((p_lo, p_med, p_hi)):
            discs = []
            below = polarity == "dark"
            # the masks are nested: the last level but one holds every lower level's pixels,
            # so those levels are thresholded and traced only in its box (texture specks
            # usually join the mask at the last level only)
            inner = _threshold(small, thresholds[-2], below)
            x, y, w, h = cv2.boundingRect(inner)
            x0, y0 = max(x - 1, 0), max(y - 1, 0)
            win = (
                slice(y0, min(y + h + 1, small.shape[0])),
                slice(x0, min(x + w + 1, small.shape[1])),
            )
            for k, thr in enumerate(thresholds):
                reach = _reach(small, polarity, thr, extreme)
                if k == len(thresholds) - 1:
                    discs += _discs(
                        _threshold(small, thr, below), min_area, k, border_only, reach, tally
                    )
                elif w > 0 and h > 0:
                    mask = (
                        inner[win]
                        if k == len(thresholds) - 2
                        else _threshold(small[win], thr, below)
                    )
                    discs += _discs(
                        mask, min_area, k, border_only, reach, tally, small.shape, (x0, y0)
                    )
            found[polarity] = (thresholds, _group(discs))
        if any(holes for _, holes in found.values()):
            break
    if stats is not None:
        stats["regions"] = tally[0]
    _cross_polarity(found)
    bores = _bores_in_bright_rings(small, found, min_area, (ox, oy))
    if bores:
        return bores
    # dark discs that hold over levels, else bright ones, else any dark, else any bright
    order = [(p, t, [h for h in hs if h[8] >= 2]) for p, (t, hs) in found.items()]
    order += [(p, t, hs) for p, (t, hs) in found.items()]
    for polarity, thresholds, holes in order:
        if holes:
            if others is not None:
                others += [_candidate(h, p, t, (ox, oy)) for p, (t, hs) in found.items()
                           if p != polarity for h in hs if h[8] >= 2]  # fmt: skip
            return [_candidate(h, polarity, thresholds, (ox, oy)) for h in holes]
    return []


def _bores_in_bright_rings(small, found, min_area: float, origin) -> list[HoleCandidate]:
    """Dark bores centred in bright discs (a flange or washer on a dark background).

    When the image is mostly dark (black cloth, a dark part), the bore is not darker than
    the median and the dark class finds nothing; a bright disc is then searched inside,
    with a ladder between the darkest and the median level *within* the disc, for a dark
    disc at its centre (within 15 % of its radius, 20 … 95 % of its size; the ladder runs
    up to the disc's 80 % quantile, the ring, since the bore may fill half the disc): that is the
    hole, the bright disc its flange. Returns those bores (full-resolution candidates).
    """
    if "bright" not in found or found.get("dark", (None, []))[1]:
        return []
    out = []
    for b in found["bright"][1]:
        cx, cy, area, (x, y, w, h), border = b[:5]
        rb = np.sqrt(area / np.pi)
        if border or rb < 4:
            continue
        crop = np.ascontiguousarray(small[y : y + h, x : x + w])
        yy, xx = np.mgrid[0:h, 0:w]
        disc = ((xx + x - cx) ** 2 + (yy + y - cy) ** 2 < rb * rb).astype(np.uint8)
        hist = cv2.calcHist([crop], [0], disc, [256], [0, 256]).ravel()
        cdf = np.cumsum(hist) / max(hist.sum(), 1.0)
        p_lo, p_med = (float(np.searchsorted(cdf, q)) for q in (0.001, 0.8))  # ring: bright
        if p_med - p_lo < 0.2 * 255:
            continue
        thresholds = [p_lo + f * (p_med - p_lo) for f in LADDER]
        discs = []
        for k, thr in enumerate(thresholds):
            mask = (crop <= thr) & (disc > 0)
            reach = _reach(crop, "dark", thr, p_lo)
            discs += _discs(mask, min_area, k, False, reach)
        for d in _group(discs):
            dx, dy = d[0] + x, d[1] + y
            rd = np.sqrt(d[2] / np.pi)
            if np.hypot(dx - cx, dy - cy) < 0.15 * rb and 0.2 * rb < rd < 0.95 * rb:
                bx, by, bw, bh = d[3]
                moved = (dx, dy, d[2], (bx + x, by + y, bw, bh), False, d[5], d[6])
                out.append(_candidate(moved, "dark", thresholds, origin))
    return out


def _candidate(hole: tuple, polarity: str, thresholds: list[float], origin) -> HoleCandidate:
    """A :class:`HoleCandidate` (full-resolution pixels) from a :func:`_group` entry."""
    s = SEARCH_SCALE
    ox, oy = origin
    cx, cy, area, (bx, by, bw, bh), border, level = hole[:6]
    others = hole[7] if len(hole) > 7 else ()
    return HoleCandidate(
        centroid_px=(cx * s + s // 2 + ox, cy * s + s // 2 + oy),
        bbox=(bx * s + ox, by * s + oy, bw * s, bh * s),
        diameter_px=float(2.0 * np.sqrt(area / np.pi) * s),
        polarity=polarity,
        threshold=float(thresholds[level]) / 255.0,
        touches_border=border,
        levels=hole[6] if len(hole) > 6 else 1,
        alternates=tuple(_candidate(o, polarity, thresholds, origin) for o in others),
    )
