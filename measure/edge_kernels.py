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
