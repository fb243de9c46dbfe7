"""Area-integrated reflectance of a calibration plate's pattern at pixels, compiled by Numba.

A pixel is a unit square. A straight edge at signed distance ``d`` (pixels, positive: the
pixel centre lies on the covered side) with unit normal ``(n_x, n_y)`` covers the fraction
``P(n_x X + n_y Y < d)`` of the pixel, X and Y uniform on [-1/2, 1/2]: the CDF of the sum of
two uniforms of widths ``|n_x|`` and ``|n_y|`` (a trapezoid), piecewise linear and quadratic
(:func:`edge_coverage`). That is the limit of infinitely many point samples per pixel.

Each pixel's plate coordinates ``(u, v)`` (pitches) and their pixel gradients (central
differences) give every edge's normal and distance. Pixels farther than 0.75 px from every
edge take the value at their centre; the others are integrated: exact along straight edges,
circle edges corrected for their curvature (the disc falls short of its tangent line by
``kappa / 24`` px on average over a pixel), and within a pixel of a chessboard corner the two
edges' coverages are multiplied (point-symmetric about the corner, so it cannot move the
corner). Assumes a pitch of several pixels. Compiled on first use and cached beside this
file (``cache=True``).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

#: reflectance of the black and white print and of what lies around the plate
BLACK, WHITE, SURROUND = 0.08, 0.92, 0.25
#: pattern kinds of :func:`plate_image`
CHESSBOARD, CIRCLES = 0, 1


@njit(cache=True)
def edge_coverage(d: float, gx: float, gy: float) -> float:
    """Fraction (0..1) of a pixel on the side ``f > 0`` of a straight edge ``f = 0``, its
    centre at signed distance ``d`` (px), ``(gx, gy)`` the gradient of ``f`` (any scale)."""
    g = math.sqrt(gx * gx + gy * gy) + 1e-300
    a, b = abs(gx) / g, abs(gy) / g
    hi, lo = max(a, b), max(min(a, b), 1e-9)
    t = abs(d)
    q = min(max(0.5 * (hi + lo) - t, 0.0), lo)
    half = 1.0 - q * q / (2.0 * hi * lo) - max(0.5 * (hi - lo) - t, 0.0) / hi
    return half if d >= 0.0 else 1.0 - half


@njit(cache=True)
def _band(f: float, lo: float, hi: float, gx: float, gy: float) -> float:
    """Fraction of a pixel where ``lo < f < hi`` (band much wider than a pixel)."""
    g = math.sqrt(gx * gx + gy * gy) + 1e-300
    return edge_coverage((f - lo) / g, gx, gy) - edge_coverage((f - hi) / g, gx, gy)


@njit(cache=True)
def _sides(u: float, gx: float, gy: float, lo: float, hi: float) -> tuple[float, float]:
    """Coverage of a pixel by "even" squares (``floor(u)`` even) and by "odd" ones, both only
    for ``lo < u < hi`` (integers); the pixel is near the line ``u = round(u)``."""
    k = math.floor(u + 0.5)
    g = math.sqrt(gx * gx + gy * gy) + 1e-300
    right = edge_coverage((u - k) / g, gx, gy)  # part of the pixel at u > k
    r = right if lo <= k < hi else 0.0
    left = 1.0 - right if lo < k <= hi else 0.0
    if int(k) % 2 == 0:  # the square right of line k is even
        return r, left
    return left, r


@njit(cache=True)
def _pixel(kind, u, v, ux, uy, vx, vy, cols, rows, radius, ulo, uhi, vlo, vhi) -> float:
    """Reflectance of one pixel: plate coordinates ``(u, v)`` (pitches), their gradients."""
    mu = 0.75 * math.sqrt(ux * ux + uy * uy)
    mv = 0.75 * math.sqrt(vx * vx + vy * vy)
    near = abs(u - ulo) < mu or abs(u - uhi) < mu or abs(v - vlo) < mv or abs(v - vhi) < mv
    on = ulo < u < uhi and vlo < v < vhi
    if kind == CHESSBOARD:
        near = near or abs(u - math.floor(u + 0.5)) < mu or abs(v - math.floor(v + 0.5)) < mv
        if not near:
            if not on:
                return SURROUND
            inside = -1.0 < u < cols and -1.0 < v < rows
            black = inside and int(math.floor(u) + math.floor(v)) % 2 == 0
            return BLACK if black else WHITE
        ue, uo = _sides(u, ux, uy, -1.0, cols)
        ve, vo = _sides(v, vx, vy, -1.0, rows)
        cover = ue * ve + uo * vo
    else:
        i = min(max(math.floor(v + 0.5), 0.0), rows - 1.0)
        odd = float(int(i) % 2)
        j = min(max(math.floor((u - odd) / 2.0 + 0.5), 0.0), cols - 1.0)
        du, dv = u - (2.0 * j + odd), v - i
        r = math.sqrt(du * du + dv * dv) + 1e-12
        gx, gy = (du * ux + dv * vx) / r, (du * uy + dv * vy) / r  # grad r, pixels
        g = math.sqrt(gx * gx + gy * gy) + 1e-300
        if not near and abs(r - radius) >= 0.75 * g:
            if not on:
                return SURROUND
            return BLACK if r < radius else WHITE
        # the edge's curvature (1/px): kappa = |J tau|^2 / (r |grad r|), tau the unit tangent
        tx, ty = -gy / g, gx / g
        ju, jv = ux * tx + uy * ty, vx * tx + vy * ty
        kappa = (ju * ju + jv * jv) / (r * g)
        cover = 1.0 - edge_coverage((r - radius) / g + kappa / 24.0, gx, gy)
    print_ = WHITE - (WHITE - BLACK) * cover
    onf = _band(u, ulo, uhi, ux, uy) * _band(v, vlo, vhi, vx, vy)
    return SURROUND + (print_ - SURROUND) * onf


@njit(cache=True)
def plate_image(nx, ny, box, H, kind, cols, rows, radius, bounds, light, out) -> None:
    """Write the image of the plate into ``out`` ((h, w) float32): the reflectance of every
    pixel times its illumination ``gain (1 - strength r^2 / r_corner^2)``.

    ``nx``, ``ny`` (h, w): the pixels' rays ``(nx, ny, 1)``; ``box`` (x0, y0, x1, y1): the
    pixels that may see the plate (the others see the surround). ``H`` (3, 3) maps a ray to
    homogeneous plate coordinates in pitches (``u = H[0] . d / H[2] . d``); rays with
    ``H[2] . d <= 0`` miss the plate's front. ``bounds`` = (u_lo, u_hi, v_lo, v_hi) of the
    plate (pitches); ``radius``: circle radius (pitches); ``light`` = (gain, strength, cx, cy,
    r_corner^2).
    """
    h, w = out.shape
    gain, strength, cx, cy, rc2 = light[0], light[1], light[2], light[3], light[4]
    x0, y0, x1, y1 = box[0], box[1], box[2], box[3]
    bh, bw = y1 - y0, x1 - x0
    U = np.empty((bh, bw))
    V = np.empty((bh, bw))
    front = np.empty((bh, bw), dtype=np.bool_)
    for r in range(bh):
        for c in range(bw):
            x, y = float(nx[y0 + r, x0 + c]), float(ny[y0 + r, x0 + c])
            den = H[2, 0] * x + H[2, 1] * y + H[2, 2]
            front[r, c] = den > 0.0
            U[r, c] = (H[0, 0] * x + H[0, 1] * y + H[0, 2]) / den
            V[r, c] = (H[1, 0] * x + H[1, 1] * y + H[1, 2]) / den
    ulo, uhi, vlo, vhi = bounds[0], bounds[1], bounds[2], bounds[3]
    for yy in range(h):
        r = yy - y0
        r0, r1 = max(r - 1, 0), min(r + 1, bh - 1)
        dy2 = (yy - cy) * (yy - cy)
        for xx in range(w):
            c = xx - x0
            lit = gain * (1.0 - strength * ((xx - cx) * (xx - cx) + dy2) / rc2)
            if r < 0 or r >= bh or c < 0 or c >= bw or not front[r, c]:
                out[yy, xx] = SURROUND * lit
                continue
            c0, c1 = max(c - 1, 0), min(c + 1, bw - 1)
            ux = (U[r, c1] - U[r, c0]) / (c1 - c0)
            uy = (U[r1, c] - U[r0, c]) / (r1 - r0)
            vx = (V[r, c1] - V[r, c0]) / (c1 - c0)
            vy = (V[r1, c] - V[r0, c]) / (r1 - r0)
            refl = _pixel(
                kind, U[r, c], V[r, c], ux, uy, vx, vy, cols, rows, radius, ulo, uhi, vlo, vhi
            )
            out[yy, xx] = refl * lit
