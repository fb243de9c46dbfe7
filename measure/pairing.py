"""Which left candidate and which right candidate are the same hole.

Every left/right pair of candidates is checked, even when each image has only one:

- **epipolar**: after rectification both centroids lie on the same row, within
  max(6 px, 10 % of the diameter) (the centroid of a tilted hole's image is not exactly
  the image of its centre, but far closer than that);
- **size**: two views of one hole differ in apparent diameter by less than 25 % (when
  they do not, the same holes' regions at the detector's other threshold levels are
  tried: a patchy interior gives different regions at different levels);
- **depth**: the centroids triangulate in front of both cameras and, when the standoff
  is known, within a factor 2 of it (the disparity range);
- **expected size**: with an expected diameter, the diameter implied by the pixel size
  and that depth lies within twice the size tolerance.

One pair left is the hole; several are resolved by the expected size, else refused as
ambiguous. When no pair passes, :class:`StereoMismatchError` counts what ruled them out.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from measure.calibration import StereoCalibration
from measure.detect import HoleCandidate
from measure.errors import AmbiguousHoleError, StereoMismatchError
from measure.triangulate import triangulate

#: apparent-size difference allowed between the two views of one hole
SIZE_RATIO_TOLERANCE = 0.25


@dataclass(frozen=True)
class PairCheck:
    """The figures of the chosen pair: rectified row difference (px), relative size
    difference, depth of the centroids (m) and the diameter they imply (m)."""

    dy_px: float
    size_difference: float
    depth_m: float
    diameter_m: float


def _check(a, b, pa, pb, stereo, f_px, standoff_m, expected_m, tol):
    """(failed check or None, PairCheck) for one candidate pair."""
    d = max(a.diameter_px, b.diameter_px)
    dy = float(abs(pa[1] - pb[1]))
    size = abs(a.diameter_px - b.diameter_px) / d
    X = triangulate(stereo, pa[None], pb[None], optimal=False)[0]
    z_right = (stereo.R @ X + stereo.T)[2]
    d_m = 0.5 * (a.diameter_px + b.diameter_px) * X[2] / f_px
    figures = PairCheck(dy, size, float(X[2]), float(d_m))
    if dy > max(6.0, 0.1 * d):
        return "epipolar", figures
    if size > SIZE_RATIO_TOLERANCE:
        return "size", figures
    if X[2] <= 0 or z_right <= 0 or (standoff_m and not 0.5 <= X[2] / standoff_m <= 2.0):
        return "depth", figures
    if expected_m and abs(d_m / expected_m - 1.0) > 2 * tol:
        return "expected size", figures
    return None, figures


def _best_levels(a, b, pa, pb, stereo, f_px, standoff_m, expected_m, tol, fig):
    """Of the two holes' regions at every ladder level, the passing pair closest in size."""
    best = (a, b, "size", fig)
    for a2 in (a, *a.alternates):
        for b2 in (b, *b.alternates):
            failed, fig2 = _check(a2, b2, pa, pb, stereo, f_px, standoff_m, expected_m, tol)
            if failed is None and (
                best[2] is not None or fig2.size_difference < best[3].size_difference
            ):
                best = (a2, b2, None, fig2)
    return best


def _describe(a, b, fig: PairCheck) -> str:
    return (
        f"closest: left ⌀{a.diameter_px:.0f} px at ({a.centroid_px[0]:.0f}, "
        f"{a.centroid_px[1]:.0f}) and right ⌀{b.diameter_px:.0f} px at "
        f"({b.centroid_px[0]:.0f}, {b.centroid_px[1]:.0f}): rows {fig.dy_px:.0f} px apart "
        f"after rectification, sizes {fig.size_difference:.0%} apart (at most "
        f"{SIZE_RATIO_TOLERANCE:.0%}), depth {fig.depth_m * 1e3:.0f} mm, "
        f"⌀{fig.diameter_m * 1e3:.1f} mm"
    )


def pick_pair(
    left: list[HoleCandidate],
    right: list[HoleCandidate],
    stereo: StereoCalibration,
    expected_m: float | None,
    tol: float,
    standoff_m: float | None = None,
) -> tuple[HoleCandidate, HoleCandidate, PairCheck]:
    """The left and right candidate that are one hole (see the module docstring)."""
    left, right = list(left), list(right)
    cl = stereo.undistort_rectify(np.array([c.centroid_px for c in left]), "left")
    cr = stereo.undistort_rectify(np.array([c.centroid_px for c in right]), "right")
    f_px = float(stereo.rectification.P1[0, 0])
    counts = dict.fromkeys(("epipolar", "size", "depth", "expected size"), 0)
    good, closest = [], None
    for i, a in enumerate(left):
        for j, b in enumerate(right):
            failed, fig = _check(a, b, cl[i], cr[j], stereo, f_px, standoff_m, expected_m, tol)
            if failed == "size":  # the same hole at other ladder levels may agree better
                a, b, failed, fig = _best_levels(
                    a, b, cl[i], cr[j], stereo, f_px, standoff_m, expected_m, tol, fig
                )
                left[i], right[j] = a, b
            if failed is None:
                err = abs(fig.diameter_m / expected_m - 1.0) if expected_m else 0.0
                good.append((err, i, j, fig))
                continue
            counts[failed] += 1
            rank = list(counts).index(failed)
            if closest is None or rank > closest[0]:
                closest = (rank, a, b, fig)
    if not good:
        assert closest is not None
        raise StereoMismatchError(len(left), len(right), counts, _describe(*closest[1:]))
    good.sort(key=lambda g: g[0])
    if len(good) == 1 or (expected_m and good[1][0] > 2 * good[0][0] + 0.1):
        _, i, j, fig = good[0]
        return left[i], right[j], fig
    which, side = ("left", left) if len({g[1] for g in good}) > 1 else ("right", right)
    idx = sorted({g[1] if which == "left" else g[2] for g in good})
    cands = [side[k] for k in idx]
    if len(cands) < 2:  # one hole in one image, several matching ones in the other
        which, side = ("right", right) if which == "left" else ("left", left)
        idx = sorted({g[2] if which == "right" else g[1] for g in good})
        cands = [side[k] for k in idx]
    raise AmbiguousHoleError(which, [(*c.centroid_px, c.diameter_px) for c in cands])
