"""Compiled loops of the sub-pixel edge step (:mod:`measure.edges`): one pass over the edge pixels.

After Canny the parabola method needs, per edge pixel, the gradient there, the dominant
axis, the magnitudes before, at and after it along that axis, the parabola's vertex, the
edge width and the unit normal; in NumPy that is some thirty array passes and
temporaries over a few hundred pixels (a fifth of the step's time on a ⌀10 mm hole),
here one loop. Compiled on first use and cached beside this file (``cache=True``). A
test checks them against the NumPy expressions they replace.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def parabola_points(xs, ys, gx, gy, mag):
    """Sub-pixel points of the edge pixels ``xs, ys`` (ints, at least 1 px inside the
    float32 images ``gx, gy, mag``) by the parabola through the magnitudes along the
    dominant gradient axis; only pixels where it is a maximum within half a pixel.

    Returns the points (M, 2, float64, image pixels), the magnitude at each (float64), the
    gradient there (float32 each), the edge width (px; inf where the log-magnitude is
    not concave) and the unit normal (M, 2): as the array expressions these replaced
    (kept in the test) and :func:`measure.edges._edge_widths`.
    """
    n = xs.shape[0]
    pts = np.empty((n, 2))
    strength = np.empty(n)
    gxo = np.empty(n, np.float32)
    gyo = np.empty(n, np.float32)
    width = np.empty(n)
    normal = np.empty((n, 2))
    m = 0
    for i in range(n):
        x, y = xs[i], ys[i]
        a, b = gx[y, x], gy[y, x]
        horiz = abs(a) >= abs(b)
        sx, sy = (1, 0) if horiz else (0, 1)
        g0 = np.float64(mag[y, x])
        gm = np.float64(mag[y - sy, x - sx])
        gp = np.float64(mag[y + sy, x + sx])
        den = gm - 2.0 * g0 + gp
        if not (den < 0 and g0 >= gm and g0 >= gp):
            continue
        off = 0.5 * (gm - gp) / den
        if not abs(off) <= 0.5:
            continue
        pts[m, 0] = x + off * sx
        pts[m, 1] = y + off * sy
        strength[m] = g0
        gxo[m], gyo[m] = a, b
        lg0 = np.log(max(g0, 1e-12))
        curv = np.log(max(gm, 1e-12)) - 2.0 * lg0 + np.log(max(gp, 1e-12))
        g = max(np.float64(np.hypot(a, b)), 1e-12)
        along = (abs(a) if horiz else abs(b)) / g
        width[m] = np.sqrt(-1.0 / curv) * along if curv < 0 else np.inf
        s = max(g0, 1e-12)
        normal[m, 0] = a / s
        normal[m, 1] = b / s
        m += 1
    return pts[:m], strength[:m], gxo[:m], gyo[:m], width[:m], normal[:m]


@njit(cache=True)
def slope_queries(pts, normals, center, offset_px):
    """Where :func:`measure.slope.slope_shift` reads the inside slope: per point, whether
    its normal points into the hole (toward ``center``), the point moved ``offset_px``
    along the normal to the inside (x and y as float32 (N, 1) maps for ``cv2.remap``),
    and the point's angle about ``center`` (rad)."""
    n = pts.shape[0]
    inward = np.empty(n, np.bool_)
    qx = np.empty((n, 1), np.float32)
    qy = np.empty((n, 1), np.float32)
    ang = np.empty(n)
    for i in range(n):
        dx, dy = pts[i, 0] - center[0], pts[i, 1] - center[1]
        inward[i] = -dx * normals[i, 0] - dy * normals[i, 1] > 0
        f = (1.0 if inward[i] else -1.0) * offset_px
        qx[i, 0] = pts[i, 0] + f * normals[i, 0]
        qy[i, 0] = pts[i, 1] + f * normals[i, 1]
        ang[i] = np.arctan2(dy, dx)
    return inward, qx, qy, ang


@njit(cache=True)
def slope_offsets(sx, sy, normals, peak, inward, tail, sigma_px):
    """x* per point (:mod:`measure.slope`) from the gradient samples ``sx, sy`` (float32)
    read inside: the inside slope along the normal less the step's own Gaussian tail
    (``tail`` × peak), over √(2π) σ × peak, signed by the side; 0 where not finite."""
    n = peak.shape[0]
    out = np.empty(n)
    k = np.sqrt(2.0 * np.pi)
    for i in range(n):
        s = np.float64(sx[i]) * normals[i, 0] + np.float64(sy[i]) * normals[i, 1]
        s -= peak[i] * tail
        num = s if inward[i] else 0.0 - s
        x = num * sigma_px / (k * peak[i]) if peak[i] != 0.0 else np.inf
        out[i] = x if np.isfinite(x) else 0.0
    return out


@njit(cache=True)
def curvature_polar(pts, cx, cy, a, b, c, s, sigma_px, ox, oy):
    """:func:`measure.contour.curvature_correction` of the points (N, 2) for the ellipse
    centred at (cx, cy) with half axes a, b along (c, s) and blur ``sigma_px``, then the
    corrected points' angle and distance about (ox, oy): one pass."""
    n = pts.shape[0]
    out = np.empty((n, 2))
    theta = np.empty(n)
    r = np.empty(n)
    k = 0.5 * sigma_px**2
    for i in range(n):
        dx, dy = pts[i, 0] - cx, pts[i, 1] - cy
        u = dx * c + dy * s
        v = dy * c - dx * s
        phi = np.arctan2(v / b, u / a)
        cp, sp = np.cos(phi), np.sin(phi)
        kappa = a * b / (a * a * sp**2 + b * b * cp**2) ** 1.5
        nu, nv = cp / a, sp / b
        shift = k * kappa / np.hypot(nu, nv)
        x = pts[i, 0] + shift * (nu * c - nv * s)
        y = pts[i, 1] + shift * (nu * s + nv * c)
        out[i, 0], out[i, 1] = x, y
        theta[i] = np.arctan2(y - oy, x - ox)
        r[i] = np.hypot(x - ox, y - oy)
    return out, theta, r


@njit(cache=True)
def periodic_median(values, window):
    """Running median over ``window`` (odd) neighbours of a periodic sequence (n ≥ window):
    ``scipy.ndimage.median_filter(values, size=window, mode="wrap")``, the middle value of
    each window being picked as that does (an element, so the same to the bit), without
    its per-call set-up (which was most of its time on a few hundred values)."""
    n = values.shape[0]
    h = window // 2
    out = np.empty(n)
    buf = np.empty(window)
    for i in range(n):
        for k in range(window):
            buf[k] = values[(i - h + k) % n]
        for k in range(1, window):  # insertion sort: a dozen values
            v = buf[k]
            m = k - 1
            while m >= 0 and buf[m] > v:
                buf[m + 1] = buf[m]
                m -= 1
            buf[m + 1] = v
        out[i] = buf[h]
    return out


@njit(cache=True)
def scaled_int16(gx, gy, scale):
    """``(gx * scale).astype(np.int16)`` and the same of ``gy`` (float32 images and scale:
    the product rounded to float32, then truncated toward zero), Canny's input, in one
    pass without the float32 temporaries."""
    h, w = gx.shape
    dx = np.empty((h, w), np.int16)
    dy = np.empty((h, w), np.int16)
    for i in range(h):
        for j in range(w):
            dx[i, j] = np.int16(gx[i, j] * scale)
            dy[i, j] = np.int16(gy[i, j] * scale)
    return dx, dy


@njit(cache=True)
def binary_moments(mask):
    """m00, m10, m01 of a 0/nonzero ``uint8`` image (pixel counts and coordinate sums, as
    ``cv2.moments(mask, binaryImage=True)``; integers, so the same to the bit)."""
    m00 = 0
    m10 = 0
    m01 = 0
    h, w = mask.shape
    for i in range(h):
        n = 0
        sx = 0
        for j in range(w):
            if mask[i, j]:
                n += 1
                sx += j
        m00 += n
        m10 += sx
        m01 += n * i
    return float(m00), float(m10), float(m01)


@njit(cache=True)
def ring_histogram(img, dist, lo, hi):
    """Gray-level counts (256, of a ``uint8`` image) of the pixels whose float32 distance
    ``dist`` lies in [lo, hi] (float32 bounds): ``cv2.calcHist`` under
    :func:`measure.masks.ring_mask` in one pass, without the mask."""
    h = np.zeros(256, np.int64)
    for i in range(img.shape[0]):
        for j in range(img.shape[1]):
            d = dist[i, j]
            if d >= lo and d <= hi:
                h[img[i, j]] += 1
    return h
