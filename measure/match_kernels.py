"""Compiled loop of the left/right matching (:mod:`measure.match`): one flank into another.

Matching a flank of one contour into the other image's flank is a binary search and a
linear interpolation per sample; in NumPy some twenty array passes per flank and
direction. Here one loop, with NumPy's ``searchsorted`` replicated (its bounds carried
from one key to the next, as NumPy does: the destination flank need not be sorted, and
the result is then NumPy's to the index). Compiled on first use and cached beside this
file (``cache=True``); a test checks it against the array expressions.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def _less(a, b):
    """NumPy's sort order of floats (NaN last)."""
    return a < b or (b != b and a == a)


@njit(cache=True)
def searchsorted_left(arr, keys):
    """``np.searchsorted(arr, keys)`` (side "left"), the same algorithm as NumPy's."""
    n = arr.shape[0]
    out = np.empty(keys.shape[0], np.int64)
    lo, hi = 0, n
    last = keys[0] if keys.shape[0] else 0.0
    for i in range(keys.shape[0]):
        key = keys[i]
        if _less(last, key):
            hi = n
        else:
            lo = 0
            hi = hi + 1 if hi < n else n
        last = key
        while lo < hi:
            mid = lo + ((hi - lo) >> 1)
            if _less(arr[mid], key):
                lo = mid + 1
            else:
                hi = mid
        out[i] = lo
    return out


@njit(cache=True)
def match_flank(src, fs, dst, fd, steep_src, steep_dst, src_w, dst_w, src_f, dst_f):
    """Samples ``fs`` of ``src`` matched on their rows into the flank ``fd`` of ``dst``
    (rectified contours (N, 2); indices in contour order, top to bottom), as the loop
    body of :func:`measure.match._one_way`: the flank's samples that go down from their
    predecessor, a row search and linear interpolation along the flank; kept where inside
    it and steep at both ends. Returns x, y, weight, filled and the source index of the
    kept matches, or ``ok = False`` when the flank has fewer than 4 such samples."""
    keep = np.empty(fd.shape[0], np.bool_)
    m = 0
    for i in range(fd.shape[0]):
        keep[i] = i == 0 or dst[fd[i], 1] - dst[fd[i - 1], 1] > 0
        m += keep[i]
    g = np.empty(m, np.int64)
    yd = np.empty(m)
    xd = np.empty(m)
    j = 0
    for i in range(fd.shape[0]):
        if keep[i]:
            g[j] = fd[i]
            yd[j], xd[j] = dst[fd[i], 1], dst[fd[i], 0]
            j += 1
    n = fs.shape[0]
    xo, yo, wo = np.empty(n), np.empty(n), np.empty(n)
    fo = np.empty(n, np.bool_)
    io = np.empty(n, np.int64)
    if m < 4:
        return xo[:0], yo[:0], wo[:0], fo[:0], io[:0], False
    ys = np.empty(n)
    for i in range(n):
        ys[i] = src[fs[i], 1]
    k = searchsorted_left(yd, ys)
    c = 0
    for i in range(n):
        inside = k[i] > 0 and k[i] < m
        kk = min(max(k[i], 1), m - 1)
        lo, hi = g[kk - 1], g[kk]
        if not (inside and steep_src[fs[i]] and steep_dst[lo] and steep_dst[hi]):
            continue
        a = (ys[i] - yd[kk - 1]) / max(yd[kk] - yd[kk - 1], 1e-12)
        xo[c] = xd[kk - 1] + a * (xd[kk] - xd[kk - 1])
        yo[c] = ys[i]
        wo[c] = src_w[fs[i]] * min(dst_w[lo], dst_w[hi])
        fo[c] = src_f[fs[i]] or dst_f[lo] or dst_f[hi]
        io[c] = fs[i]
        c += 1
    return xo[:c], yo[:c], wo[:c], fo[:c], io[:c], True
