"""The stereo hole measurement pipeline, :func:`measure_hole`.

Stages (each timed): find the hole in both images → crop → Canny + sub-pixel edges →
centroid from moments and lines through it (gap filling, robust image ellipse) → rectify and
match left/right under the epipolar constraint and contour order → triangulate (optimal
correction + DLT) → Levenberg–Marquardt spatial circle fit with outlier rejection.
"""

from __future__ import annotations

import time

import numpy as np

from measure.calibration import StereoCalibration
from measure.circle import fit_circle_3d
from measure.contour import Contour, build_contour
from measure.detect import HoleCandidate, check_image, find_candidates
from measure.edges import hole_region, subpixel_edges
from measure.errors import (
    AmbiguousHoleError,
    EdgeError,
    HoleAtBorderError,
    HoleNotFoundError,
    HoleSizeError,
    ImageError,
)
from measure.match import match_contours
from measure.nearside import fit_with_near_side_check
from measure.result import HoleMeasurement, MeasureOptions
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


def _usable(cands: list[HoleCandidate], which: str, roi: Rect | None, shape) -> list[HoleCandidate]:
    inner = [c for c in cands if not c.touches_border]
    if inner:
        return inner
    if cands:
        raise HoleAtBorderError(which, cands[0].bbox)
    where = f" in the region {roi}" if roi is not None else ""
    raise HoleNotFoundError(
        which, f"no dark or bright disc-like region{where} ({shape[1]}x{shape[0]} px)"
    )


def _pick_pair(
    left: list[HoleCandidate],
    right: list[HoleCandidate],
    stereo: StereoCalibration,
    expected_m: float | None,
    tol: float,
) -> tuple[HoleCandidate, HoleCandidate]:
    """One candidate per image: the unique one, or the stereo pair nearest the expected size."""
    if len(left) == 1 and len(right) == 1:
        return left[0], right[0]
    if expected_m is None:
        which, cands = ("left", left) if len(left) > 1 else ("right", right)
        raise AmbiguousHoleError(which, [(*c.centroid_px, c.diameter_px) for c in cands])
    cl = stereo.undistort_rectify(np.array([c.centroid_px for c in left]), "left")
    cr = stereo.undistort_rectify(np.array([c.centroid_px for c in right]), "right")
    f = stereo.rectification.P1[0, 0]
    scored = []
    for i, a in enumerate(left):
        for j, b in enumerate(right):
            if abs(cl[i, 1] - cr[j, 1]) > max(6.0, 0.1 * a.diameter_px):
                continue  # not on the same epipolar line
            if abs(a.diameter_px - b.diameter_px) > 0.25 * max(a.diameter_px, b.diameter_px):
                continue  # two views of one hole have about the same size
            X = triangulate(stereo, cl[i : i + 1], cr[j : j + 1], optimal=False)[0]
            d_m = 0.5 * (a.diameter_px + b.diameter_px) * X[2] / f
            scored.append((abs(d_m / expected_m - 1.0), i, j))
    good = sorted(s for s in scored if s[0] <= 2 * tol)
    if len(good) == 1 or (len(good) > 1 and good[1][0] > 2 * good[0][0] + 0.1):
        return left[good[0][1]], right[good[0][2]]
    which, cands = ("left", left) if len(left) > 1 else ("right", right)
    raise AmbiguousHoleError(which, [(*c.centroid_px, c.diameter_px) for c in cands])


def _contour(img, full, cand, opts: MeasureOptions, which: str) -> tuple[Contour, Rect, float]:
    region = hole_region(img, full, cand)
    edges = subpixel_edges(img, full, region, opts.edge_method, opts.smoothing_sigma_px)
    pts = edges.points_px
    blur = edges.blur_sigma_px if opts.curvature_correction else 0.0
    contour = build_contour(
        pts, region.centroid_px, opts.arc_step_px, opts.short_gap_px, blur_sigma_px=blur
    )
    if contour is None:
        raise EdgeError(f"{which} image edges", len(edges.points_px), 12)
    return contour, region.roi, float(region.area_px)


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
) -> HoleMeasurement:
    """Measure one hole from a stereo pair.

    Args:
        left, right: single-channel ``uint8`` or ``uint16`` (12- or 16-bit) images, as
            the cameras deliver them (distorted), of the calibrated size.
        stereo: the head's calibration.
        expected_diameter_m: nominal diameter; picks the hole when several are in view
            and raises :class:`HoleSizeError` when the result is off by more than
            ``options.size_tolerance``.
        roi: ``(x, y, w, h)`` for both images, or ``((x, y, w, h), (x, y, w, h))`` for left
            and right, to restrict the search.
        options: :class:`MeasureOptions`.

    Returns:
        :class:`HoleMeasurement` in the LEFT camera optical frame (metres).

    Raises:
        MeasurementError subclasses for every bad input (see :mod:`measure.errors`).
    """
    opts = options or MeasureOptions()
    t = {}
    t0 = time.perf_counter()
    if np.shape(left) != np.shape(right):
        raise ImageError("pair", f"left is {np.shape(left)} but right is {np.shape(right)} (h, w)")
    full_l, small_l = check_image(left, "left")
    full_r, small_r = check_image(right, "right")
    stereo.check_image(left.shape, "left")
    roi_l, roi_r = _rois(roi)
    cand_l = _usable(find_candidates(small_l, roi_l), "left", roi_l, left.shape)
    cand_r = _usable(find_candidates(small_r, roi_r), "right", roi_r, right.shape)
    cl, cr = _pick_pair(cand_l, cand_r, stereo, expected_diameter_m, opts.size_tolerance)
    t["detect"] = time.perf_counter() - t0

    t1 = time.perf_counter()
    con_l, box_l, _ = _contour(left, full_l, cl, opts, "left")
    con_r, box_r, _ = _contour(right, full_r, cr, opts, "right")
    t["edges"] = time.perf_counter() - t1

    t2 = time.perf_counter()
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
    t["match"] = time.perf_counter() - t2
    if int((m.weight > 0).sum()) < 12:
        raise EdgeError("stereo matching", int((m.weight > 0).sum()), 12)

    t3 = time.perf_counter()
    if opts.robust and opts.near_side_max_angle_deg is not None:
        cams = np.stack([np.zeros(3), stereo.right_center_in_left])
        circ, _ = fit_with_near_side_check(
            pts, m.weight, cams, opts.near_side_max_angle_deg, cost=opts.circle_cost
        )
    else:
        circ = fit_circle_3d(pts, m.weight, cost=opts.circle_cost, robust=opts.robust)
    t["fit"] = time.perf_counter() - t3
    if expected_diameter_m is not None:
        d = 2 * circ.radius
        if abs(d / expected_diameter_m - 1.0) > opts.size_tolerance:
            raise HoleSizeError(d, expected_diameter_m, opts.size_tolerance)
    n_filled = int(con_l.filled.sum() + con_r.filled.sum())
    n_contour = len(con_l.points_px) + len(con_r.points_px)
    bad = n_filled + con_l.n_outliers + con_r.n_outliers + circ.n_rejected
    status = "suspect" if bad > opts.suspect_fraction * n_contour else "ok"
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
        roi_left=box_l,
        roi_right=box_r,
        options=opts,
    )
