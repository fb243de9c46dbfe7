"""Left/right matching of contour points under the epipolar constraint and contour order.

Both contours are undistorted and rectified, so epipolar lines are image rows. Each closed
contour splits at its top and bottom into two y-monotonic chains (its left and right flank);
a point of one image is matched to the point of the other image's same flank on the same
row, interpolated linearly along the contour. Points where the contour runs within
``min_angle_deg`` of the epipolar direction (top and bottom of the hole) are dropped: there a
row cuts the contour at a grazing angle and the match is ill-conditioned. Matching runs both
ways (left→right and right→left) so both images' samples are used.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from measure.match_kernels import match_flank


@dataclass(frozen=True)
class Matches:
    """Matched rectified pixel pairs (N, 2) each, their weights and where they came from.

    ``source`` is 0 for a left sample matched into the right contour, 1 for the reverse;
    ``index`` the sample index in its own contour; ``filled`` if either end was filled.
    """

    left_rect: np.ndarray
    right_rect: np.ndarray
    weight: np.ndarray
    filled: np.ndarray
    source: np.ndarray
    index: np.ndarray


def _flanks(pts: np.ndarray) -> list[np.ndarray]:
    """Index arrays of the two flanks of a closed contour (top→bottom, ordered), left first."""
    n = len(pts)
    i_top, i_bot = int(np.argmin(pts[:, 1])), int(np.argmax(pts[:, 1]))
    a = (i_top + np.arange((i_bot - i_top) % n + 1)) % n
    b = (i_bot + np.arange((i_top - i_bot) % n + 1)) % n
    b = np.ascontiguousarray(b[::-1])  # also top → bottom (contiguous: one compiled variant)
    return [a, b] if pts[a, 0].mean() <= pts[b, 0].mean() else [b, a]


def _steep(pts: np.ndarray, min_sin: float) -> np.ndarray:
    """Samples whose contour tangent is steeper than ``asin(min_sin)`` to the rows."""
    t = np.empty_like(pts)  # next minus previous sample, around the closed contour
    t[1:-1] = pts[2:] - pts[:-2]
    t[0] = pts[1] - pts[-1]
    t[-1] = pts[0] - pts[-2]
    return np.abs(t[:, 1]) > min_sin * np.hypot(t[:, 0], t[:, 1])


def _one_way(src, src_w, src_f, dst, dst_w, dst_f, steep_src, steep_dst, flanks_src, flanks_dst):
    """Match samples of ``src`` into the contour ``dst`` (both rectified, ordered, closed;
    their :func:`_steep` masks and :func:`_flanks` given)."""
    out_x, out_w, out_f, out_i = [], [], [], []
    for fs, fd in zip(flanks_src, flanks_dst, strict=True):
        x, ys, w, f, i, ok = match_flank(
            src, fs, dst, fd, steep_src, steep_dst, src_w, dst_w, src_f, dst_f
        )
        if not ok:
            continue
        out_x.append(np.stack([x, ys], axis=1))
        out_w.append(w)
        out_f.append(f)
        out_i.append(i)
    if not out_x:
        return np.zeros((0, 2)), np.zeros(0), np.zeros(0, bool), np.zeros(0, int)
    return (
        np.concatenate(out_x),
        np.concatenate(out_w),
        np.concatenate(out_f),
        np.concatenate(out_i),
    )


def match_contours(
    left_rect: np.ndarray,
    left_weight: np.ndarray,
    left_filled: np.ndarray,
    right_rect: np.ndarray,
    right_weight: np.ndarray,
    right_filled: np.ndarray,
    min_angle_deg: float = 20.0,
    both_ways: bool = True,
) -> Matches:
    """Match two closed rectified contours row by row, flank to flank (see module doc)."""
    min_sin = float(np.sin(np.deg2rad(min_angle_deg)))
    steep_l, steep_r = _steep(left_rect, min_sin), _steep(right_rect, min_sin)
    flanks_l, flanks_r = _flanks(left_rect), _flanks(right_rect)
    xr, wl, fl, il = _one_way(
        left_rect, left_weight, left_filled, right_rect, right_weight, right_filled,
        steep_l, steep_r, flanks_l, flanks_r,
    )  # fmt: skip
    Ls, Rs, Ws, Fs, Ss, Is = [left_rect[il]], [xr], [wl], [fl], [np.zeros(len(il), int)], [il]
    if both_ways:
        xl, wr, fr, ir = _one_way(
            right_rect, right_weight, right_filled, left_rect, left_weight, left_filled,
            steep_r, steep_l, flanks_r, flanks_l,
        )  # fmt: skip
        Ls.append(xl)
        Rs.append(right_rect[ir])
        Ws.append(wr)
        Fs.append(fr)
        Ss.append(np.ones(len(ir), int))
        Is.append(ir)
    return Matches(
        left_rect=np.concatenate(Ls),
        right_rect=np.concatenate(Rs),
        weight=np.concatenate(Ws),
        filled=np.concatenate(Fs),
        source=np.concatenate(Ss),
        index=np.concatenate(Is),
    )
