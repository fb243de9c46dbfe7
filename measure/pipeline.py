"""The stereo hole measurement pipeline, :func:`measure_hole`.

Stages (each timed): find the hole in both images → crop → Canny + sub-pixel edges →
centroid from moments and lines through it (gap filling, robust image ellipse) → rectify and
match left/right under the epipolar constraint and contour order → triangulate (optimal
correction + DLT) → Levenberg–Marquardt spatial circle fit with outlier rejection.
"""

from __future__ import annotations

import time
from collections.abc import Sequence

import numpy as np

from measure.calibration import StereoCalibration
from measure.circle import fit_circle_3d
from measure.contour import Contour, build_contour
from measure.detect import SEARCH_SCALE, HoleCandidate, check_image, find_candidates, to_gray
from measure.edges import HoleRegion, hole_region, subpixel_edges
from measure.errors import (
    AmbiguousHoleError,
    EdgeError,
    HoleAtBorderError,
    HoleNotFoundError,
    HoleSizeError,
    ImageError,
    StereoMismatchError,
)
from measure.match import match_contours
from measure.nearside import fit_with_near_side_check
from measure.opening import surface_level_search, with_wall_crescent
from measure.pairing import pick_pair
from measure.result import HoleMeasurement, MeasureOptions, RimChoice
from measure.triangulate import triangulate

Rect = tuple[int, int, int, int]


def _rois(roi) -> tuple[Rect | None, Rect | None]:
    if roi is None:
        return None, None
    arr = np.asarray(roi, dtype=int)
    if arr.shape == (4,):
        return tuple(arr), tuple(arr)
    if arr.shape == (2, 4):
        return tuple(arr[0]), tuple(arr[1])
    raise ValueError(f"roi must be (x, y, w, h) or a pair of them, got {roi!r}")


def _usable(
    cands: list[HoleCandidate], which: str, roi: Rect | None, shape, stats: dict
) -> list[HoleCandidate]:
    inner = [c for c in cands if not c.touches_border]
    if inner:
        return inner
    if cands:
        raise HoleAtBorderError(which, cands[0].bbox)
    where = f" in the region {roi}" if roi is not None else ""
    con = stats.get("contrast", {})
    searched = [k for k, v in con.items() if v >= 0.2]
    if searched:
        why = (
            f"{stats.get('regions', 0)} compact regions of the "
            f"{' and '.join(searched)} class{'es' if len(searched) > 1 else ''} at five "
            "threshold levels, none disc-like"
        )
    else:
        why = (
            f"too little contrast to search: dark {con.get('dark', 0.0):.0%}, bright "
            f"{con.get('bright', 0.0):.0%} of full scale from the median (20 % needed)"
        )
    raise HoleNotFoundError(
        which, f"no dark or bright disc-like region{where} ({shape[1]}x{shape[0]} px): {why}"
    )


def _contour(img, full, cand, opts: MeasureOptions, which: str) -> tuple[Contour, HoleRegion]:
    region = hole_region(img, full, cand)
    edges = subpixel_edges(
        img, full, region, opts.edge_method, opts.smoothing_sigma_px, opts.slope_correction
    )
    pts = edges.points_px
    blur = edges.blur_sigma_px if opts.curvature_correction else 0.0
    contour = build_contour(
        pts, region.centroid_px, opts.arc_step_px, opts.short_gap_px, blur_sigma_px=blur
    )
    if contour is None:
        raise EdgeError(
            f"{which} image edges (hole region ⌀{cand.diameter_px:.0f} px at "
            f"({cand.centroid_px[0]:.0f}, {cand.centroid_px[1]:.0f}))",
            len(edges.points_px),
            12,
        )
    return contour, region


def _surface_level(small: np.ndarray, cand: HoleCandidate) -> float:
    """Median of the search image on circles 1.0 … 1.5 diameters from the hole's centre:
    the part's surface beyond any grommet or washer (fraction of full scale)."""
    s = SEARCH_SCALE
    cx, cy = (cand.centroid_px[0] - s // 2) / s, (cand.centroid_px[1] - s // 2) / s
    return surface_level_search(small, cx, cy, cand.diameter_px / s) / 255.0


def _rim(cl, cr, reg_l, reg_r, small_l, small_r, depth_m) -> RimChoice:
    """Describe the edge used; ``surround`` is "ring" when outside the rim is not the surface."""
    surf = (_surface_level(small_l, cl), _surface_level(small_r, cr))
    rings = [
        max(abs(r.outside_level - s), abs(r.ring_level - s)) > 0.15 * abs(r.inside_level - s) + 0.02
        for r, s in zip((reg_l, reg_r), surf, strict=True)
    ]
    return RimChoice(
        polarity=cl.polarity,
        surround="ring" if all(rings) else "surface",
        diameter_px=(2 * np.sqrt(reg_l.area_px / np.pi), 2 * np.sqrt(reg_r.area_px / np.pi)),
        levels=(cl.levels, cr.levels),
        inside_level=(reg_l.inside_level, reg_r.inside_level),
        outside_level=(reg_l.outside_level, reg_r.outside_level),
        ring_level=(reg_l.ring_level, reg_r.ring_level),
        surface_level=surf,
        depth_m=depth_m,
    )


def _suspect_reasons(
    opts: MeasureOptions,
    bad: int,
    n_contour: int,
    rms_m: float,
    px_m: float,
    rim: RimChoice,
    rows: tuple[float, float],
) -> tuple[str, ...]:
    """Why a measurement is suspect (thresholds: :class:`MeasureOptions`)."""
    out = []
    if max(rows) > opts.suspect_epipolar_px:
        out.append(
            f"the rims' top and bottom rows differ by {rows[0]:.1f} / {rows[1]:.1f} px after "
            f"rectification (at most {opts.suspect_epipolar_px:g} px): the cameras see "
            "different rims (a chamfer or lip seen from two sides) or the calibration does "
            "not fit the images"
        )
    if bad > opts.suspect_fraction * n_contour:
        out.append(
            f"{bad} of {n_contour} contour samples filled or rejected "
            f"(more than {opts.suspect_fraction:.0%})"
        )
    rms_limit = max(opts.suspect_rms_m, opts.suspect_rms_px * px_m)
    if rms_m > rms_limit:
        out.append(
            f"fit RMS {rms_m * 1e6:.1f} µm ({rms_m / px_m:.2f} px) above "
            f"{rms_limit * 1e6:.1f} µm (max of {opts.suspect_rms_m * 1e6:.0f} µm and "
            f"{opts.suspect_rms_px:g} px)"
        )
    contrast = [abs(o - i) for i, o in zip(rim.inside_level, rim.outside_level, strict=True)]
    diff = max(
        abs(rim.inside_level[0] - rim.inside_level[1]),
        abs(rim.outside_level[0] - rim.outside_level[1]),
    )
    if diff > opts.suspect_rim_mismatch * max(min(contrast), 1e-6):
        out.append(
            f"left and right rims differ: gray levels inside/outside "
            f"{rim.inside_level[0]:.2f}/{rim.outside_level[0]:.2f} vs "
            f"{rim.inside_level[1]:.2f}/{rim.outside_level[1]:.2f}"
        )
    return tuple(out)


#: a circle in image pixels: centre x, centre y, radius
Circle = tuple[float, float, float]


def _outside(cands: list[HoleCandidate], circles: Sequence[Circle]) -> list[HoleCandidate]:
    """The candidates whose centre lies in none of ``circles``."""
    return [c for c in cands
            if all((c.centroid_px[0] - x) ** 2 + (c.centroid_px[1] - y) ** 2 > r * r
                   for x, y, r in circles)]  # fmt: skip


def _pick(cand_l, cand_r, oth_l, oth_r, pair_args):
    """The left/right pair (:func:`measure.pairing.pick_pair`); when none of the returned
    candidates pair, each polarity is tried once more with the other polarity's holes
    (a dark texture blob in a dim corner taken for the hole in one image, while both show
    a lit background's opening), and a pair of exactly one polarity is taken."""
    try:
        return pick_pair(cand_l, cand_r, *pair_args)
    except StereoMismatchError as first:
        found = []
        for pol in ("dark", "bright"):
            a = [c for c in cand_l + oth_l if c.polarity == pol and not c.touches_border]
            b = [c for c in cand_r + oth_r if c.polarity == pol and not c.touches_border]
            tried = all(c in cand_l for c in a) and all(c in cand_r for c in b)
            if not a or not b or tried:
                continue
            try:
                found.append(pick_pair(a, b, *pair_args))
            except (StereoMismatchError, AmbiguousHoleError):
                continue
        if len(found) != 1:
            raise first from None
        return found[0]


def _weights(c: Contour, opts: MeasureOptions) -> np.ndarray:
    w = np.ones(len(c.points_px))
    if not opts.use_long_fills:
        w[c.long_gap] = 0.0
    return w


def measure_hole(
    left: np.ndarray,
    right: np.ndarray,
    stereo: StereoCalibration,
    expected_diameter_m: float | None = None,
    roi=None,
    options: MeasureOptions | None = None,
    expected_standoff_m: float | None = None,
    exclude: tuple[Sequence[Circle], Sequence[Circle]] | None = None,
) -> HoleMeasurement:
    """Measure one hole from a stereo pair.

    Args:
        left, right: ``uint8`` or ``uint16`` (8 … 16 significant bits) images, as the
            cameras deliver them (distorted), of the calibrated size; single-channel or
            colour ``(h, w, 3)`` BGR (converted to luma).
        stereo: the head's calibration.
        expected_diameter_m: nominal diameter; picks the hole when several are in view
            and raises :class:`HoleSizeError` when the result is off by more than
            ``options.size_tolerance``.
        roi: ``(x, y, w, h)`` for both images, or ``((x, y, w, h), (x, y, w, h))`` for left
            and right, to restrict the search.
        options: :class:`MeasureOptions`.
        expected_standoff_m: nominal depth of the hole (metres, left frame); candidate
            pairs whose disparity puts them outside half to twice this depth are ruled out.
        exclude: per image (left, right), circles ``(x_px, y_px, radius_px)`` known not to
            hold the hole (reference markers' black labels, which look like dark discs): a
            candidate whose centre lies in one is not considered.

    Returns:
        :class:`HoleMeasurement` in the LEFT camera optical frame (metres).

    Raises:
        MeasurementError subclasses for every bad input (see :mod:`measure.errors`).
    """
    opts = options or MeasureOptions()
    t, cpu = {}, {}
    t0, c0 = time.perf_counter(), time.thread_time()
    left, right = to_gray(left, "left"), to_gray(right, "right")
    if left.shape != right.shape:
        raise ImageError("pair", f"left is {left.shape} but right is {right.shape} (h, w)")
    full_l, small_l = check_image(left, "left")
    full_r, small_r = check_image(right, "right")
    stereo.check_image(left.shape, "left")
    roi_l, roi_r = _rois(roi)
    st_l, st_r, oth_l, oth_r = {}, {}, [], []
    found_l = find_candidates(small_l, roi_l, stats=st_l, others=oth_l)
    found_r = find_candidates(small_r, roi_r, stats=st_r, others=oth_r)
    if exclude is not None:
        found_l, oth_l = _outside(found_l, exclude[0]), _outside(oth_l, exclude[0])
        found_r, oth_r = _outside(found_r, exclude[1]), _outside(oth_r, exclude[1])
    cand_l = _usable(found_l, "left", roi_l, left.shape, st_l)
    cand_r = _usable(found_r, "right", roi_r, right.shape, st_r)
    # a lit background's lens → the whole opening (measure.opening)
    cand_l, oth_l = ([with_wall_crescent(small_l, c) for c in cs] for cs in (cand_l, oth_l))
    cand_r, oth_r = ([with_wall_crescent(small_r, c) for c in cs] for cs in (cand_r, oth_r))
    pair_args = (stereo, expected_diameter_m, opts.size_tolerance, expected_standoff_m)
    cl, cr, check = _pick(cand_l, cand_r, oth_l, oth_r, pair_args)
    t["detect"], cpu["detect"] = time.perf_counter() - t0, time.thread_time() - c0

    t1, c1 = time.perf_counter(), time.thread_time()
    con_l, reg_l = _contour(left, full_l, cl, opts, "left")
    con_r, reg_r = _contour(right, full_r, cr, opts, "right")
    rim = _rim(cl, cr, reg_l, reg_r, small_l, small_r, check.depth_m)
    t["edges"], cpu["edges"] = time.perf_counter() - t1, time.thread_time() - c1

    t2, c2 = time.perf_counter(), time.thread_time()
    rl = stereo.undistort_rectify(con_l.points_px, "left")
    rr = stereo.undistort_rectify(con_r.points_px, "right")
    m = match_contours(
        rl,
        _weights(con_l, opts),
        con_l.filled,
        rr,
        _weights(con_r, opts),
        con_r.filled,
        opts.min_epipolar_angle_deg,
    )
    pts = triangulate(stereo, m.left_rect, m.right_rect)
    t["match"], cpu["match"] = time.perf_counter() - t2, time.thread_time() - c2
    if int((m.weight > 0).sum()) < 12:
        raise EdgeError("stereo matching", int((m.weight > 0).sum()), 12)

    t3, c3 = time.perf_counter(), time.thread_time()
    if opts.robust and opts.near_side_max_angle_deg is not None:
        cams = np.stack([np.zeros(3), stereo.right_center_in_left])
        circ, _ = fit_with_near_side_check(
            pts, m.weight, cams, opts.near_side_max_angle_deg, cost=opts.circle_cost
        )
    else:
        circ = fit_circle_3d(pts, m.weight, cost=opts.circle_cost, robust=opts.robust)
    t["fit"], cpu["fit"] = time.perf_counter() - t3, time.thread_time() - c3
    if expected_diameter_m is not None:
        d = 2 * circ.radius
        if abs(d / expected_diameter_m - 1.0) > opts.size_tolerance:
            raise HoleSizeError(d, expected_diameter_m, opts.size_tolerance)
    n_filled = int(con_l.filled.sum() + con_r.filled.sum())
    n_contour = len(con_l.points_px) + len(con_r.points_px)
    bad = n_filled + con_l.n_outliers + con_r.n_outliers + circ.n_rejected
    px_m = float(circ.center[2]) / float(stereo.K_left[0, 0])  # one pixel at the hole, m
    rows = (
        abs(float(rl[:, 1].min() - rr[:, 1].min())),
        abs(float(rl[:, 1].max() - rr[:, 1].max())),
    )
    reasons = _suspect_reasons(opts, bad, n_contour, circ.rms_m, px_m, rim, rows)
    status = "suspect" if reasons else "ok"
    total = time.perf_counter() - t0
    return HoleMeasurement(
        status=status,
        center_m=circ.center,
        normal=circ.normal,
        radius_m=circ.radius,
        rms_m=circ.rms_m,
        n_points=circ.n_used,
        n_rejected=circ.n_rejected,
        n_filled=n_filled,
        cov_center_radius=circ.cov_center_radius,
        timings=t,
        time_s=total,
        edges_left_px=con_l.points_px,
        edges_right_px=con_r.points_px,
        filled_left=con_l.filled,
        filled_right=con_r.filled,
        ellipse_left=con_l.ellipse,
        ellipse_right=con_r.ellipse,
        points_m=pts,
        inliers=circ.inliers,
        roi_left=reg_l.roi,
        roi_right=reg_r.roi,
        options=opts,
        rim=rim,
        suspect_reasons=reasons,
        cpu_timings=cpu,
    )
