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
#: beyond this distance (px) from a straight edge a pixel lies wholly on one side of it
EDGE_CLEAR_PX = 0.75


@njit(cache=True)
def edge_coverage(d: float, gx: float, gy: float) -> float:
    """Fraction (0..1) of a pixel on the side ``f > 0`` of a straight edge ``f = 0``, its
    centre at signed distance ``d`` (px), ``(gx, gy)`` the gradient of ``f`` (any scale)."""
    # a pixel is wholly on one side beyond sqrt(2)/2 px: the formula below gives exactly 1
    # or 0 there (q = 0 and the second term 0), at a fraction of the cost
    if d >= EDGE_CLEAR_PX:
        return 1.0
    if d <= -EDGE_CLEAR_PX:
        return 0.0
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
    # within 0.75 px of an edge: (distance in u)^2 < 0.75^2 |grad u|^2
    mu2 = 0.5625 * (ux * ux + uy * uy)
    mv2 = 0.5625 * (vx * vx + vy * vy)
    near = min((u - ulo) ** 2, (u - uhi) ** 2) < mu2 or min((v - vlo) ** 2, (v - vhi) ** 2) < mv2
    on = ulo < u < uhi and vlo < v < vhi
    if kind == CHESSBOARD:
        near = near or (u - math.floor(u + 0.5)) ** 2 < mu2 or (v - math.floor(v + 0.5)) ** 2 < mv2
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


#: side (px) of the blocks the plate is drawn in: a block whose corners put every pixel of it
#: well clear of every edge takes one reflectance (the per-pixel test would give each of its
#: pixels that value: the same image, bit for bit); only blocks near an edge are integrated
#: pixel by pixel (about a fifth of a chessboard view at 0.25 m)
BLOCK_PX = 8
#: how far (px of the pattern's largest gradient at the block's corners) beyond a pixel's own
#: 0.75-px edge test a block's corner interval must stay clear of an edge: the pattern
#: coordinates bulge past their corner values by ~0.01 px across a block, and their gradient
#: varies by well under 1.5x (checked) within it
BLOCK_SLACK_PX = 0.5


@njit(cache=True, inline="always")
def _lit(xx, yy, gain, strength, cx, cy, rc2) -> float:
    """Illumination ``gain (1 - strength r^2 / r_corner^2)`` of pixel ``(xx, yy)``."""
    dy2 = (yy - cy) * (yy - cy)
    return gain * (1.0 - strength * ((xx - cx) * (xx - cx) + dy2) / rc2)


@njit(cache=True, inline="always")
def _uv(nx, ny, yy, xx, H):
    """``(den, u, v, ux, uy, vx, vy)`` at pixel ``(xx, yy)``: the homography's denominator
    (``<= 0``: the ray misses the plate's front, the rest is then 0), the plate coordinates
    (pitches) and their pixel gradients."""
    h, w = nx.shape
    x, y = float(nx[yy, xx]), float(ny[yy, xx])
    den = H[2, 0] * x + H[2, 1] * y + H[2, 2]
    if den <= 0.0:
        return den, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    u = (H[0, 0] * x + H[0, 1] * y + H[0, 2]) / den
    v = (H[1, 0] * x + H[1, 1] * y + H[1, 2]) / den
    # d(u, v)/d(pixel) = d(u, v)/d(ray) (the homography, exact) x d(ray)/d(pixel)
    # (central differences of the rays)
    r0, r1 = max(yy - 1, 0), min(yy + 1, h - 1)
    c0, c1 = max(xx - 1, 0), min(xx + 1, w - 1)
    rx_x = (nx[yy, c1] - nx[yy, c0]) / (c1 - c0)
    ry_x = (ny[yy, c1] - ny[yy, c0]) / (c1 - c0)
    rx_y = (nx[r1, xx] - nx[r0, xx]) / (r1 - r0)
    ry_y = (ny[r1, xx] - ny[r0, xx]) / (r1 - r0)
    au, bu = (H[0, 0] - u * H[2, 0]) / den, (H[0, 1] - u * H[2, 1]) / den
    av, bv = (H[1, 0] - v * H[2, 0]) / den, (H[1, 1] - v * H[2, 1]) / den
    ux, uy = au * rx_x + bu * ry_x, au * rx_y + bu * ry_y
    vx, vy = av * rx_x + bv * ry_x, av * rx_y + bv * ry_y
    return den, u, v, ux, uy, vx, vy


@njit(cache=True, inline="always")
def _plate_pixel(nx, ny, yy, xx, H, kind, cols, rows, radius, ulo, uhi, vlo, vhi) -> float:
    """Reflectance of pixel ``(xx, yy)`` (the surround where its ray misses the plate)."""
    den, u, v, ux, uy, vx, vy = _uv(nx, ny, yy, xx, H)
    if den <= 0.0:
        return SURROUND
    return _pixel(kind, u, v, ux, uy, vx, vy, cols, rows, radius, ulo, uhi, vlo, vhi)


@njit(cache=True)
def _crosses(lo: float, hi: float, edge: float) -> bool:
    return lo <= edge <= hi


@njit(cache=True)
def _block_value(nx, ny, bx0, by0, bx1, by1, H, kind, cols, rows, ulo, uhi, vlo, vhi) -> float:
    """The reflectance every pixel of the block ``[bx0, bx1) x [by0, by1)`` has when no edge
    comes near any of them (off the plate; a chessboard square), else -1."""
    umin, umax, vmin, vmax = math.inf, -math.inf, math.inf, -math.inf
    gu_lo, gu_hi, gv_lo, gv_hi = math.inf, 0.0, math.inf, 0.0
    for k in range(4):
        xx = bx0 if k % 2 == 0 else bx1 - 1
        yy = by0 if k < 2 else by1 - 1
        den, u, v, ux, uy, vx, vy = _uv(nx, ny, yy, xx, H)
        if den <= 0.0:
            return -1.0
        umin, umax, vmin, vmax = min(umin, u), max(umax, u), min(vmin, v), max(vmax, v)
        gu, gv = math.sqrt(ux * ux + uy * uy), math.sqrt(vx * vx + vy * vy)
        gu_lo, gu_hi, gv_lo, gv_hi = min(gu_lo, gu), max(gu_hi, gu), min(gv_lo, gv), max(gv_hi, gv)
    if gu_hi > 1.5 * gu_lo or gv_hi > 1.5 * gv_lo:
        return -1.0
    du, dv = (0.75 + BLOCK_SLACK_PX) * gu_hi, (0.75 + BLOCK_SLACK_PX) * gv_hi
    u0, u1, v0, v1 = umin - du, umax + du, vmin - dv, vmax + dv
    if (
        _crosses(u0, u1, ulo)
        or _crosses(u0, u1, uhi)
        or _crosses(v0, v1, vlo)
        or _crosses(v0, v1, vhi)
    ):
        return -1.0
    if not (ulo < u0 and u1 < uhi and vlo < v0 and v1 < vhi):
        return SURROUND  # wholly off the plate, clear of its outline
    if kind != CHESSBOARD or math.floor(u0) != math.floor(u1) or math.floor(v0) != math.floor(v1):
        return -1.0
    u, v = 0.5 * (umin + umax), 0.5 * (vmin + vmax)
    inside = -1.0 < u < cols and -1.0 < v < rows
    black = inside and int(math.floor(u) + math.floor(v)) % 2 == 0
    return BLACK if black else WHITE


@njit(cache=True)
def plate_region(nx, ny, region, box, H, kind, cols, rows, radius, bounds, light, out) -> None:
    """Write the image of the plate over the pixels ``region`` = (x0, y0, x1, y1) into ``out``
    ((y1 - y0, x1 - x0) float32): the reflectance of every pixel times its illumination
    ``gain (1 - strength r^2 / r_corner^2)``.

    ``nx``, ``ny`` (h, w): the pixels' rays ``(nx, ny, 1)``; ``box`` (x0, y0, x1, y1): the
    pixels that may see the plate (the others see the surround). ``H`` (3, 3) maps a ray to
    homogeneous plate coordinates in pitches (``u = H[0] . d / H[2] . d``); rays with
    ``H[2] . d <= 0`` miss the plate's front. ``bounds`` = (u_lo, u_hi, v_lo, v_hi) of the
    plate (pitches); ``radius``: circle radius (pitches); ``light`` = (gain, strength, cx, cy,
    r_corner^2). Drawn in blocks of ``BLOCK_PX``: each pixel gets the value the per-pixel
    integral gives it.
    """
    gain, strength, cx, cy, rc2 = light[0], light[1], light[2], light[3], light[4]
    rx0, ry0, rx1, ry1 = region[0], region[1], region[2], region[3]
    x0, y0, x1, y1 = box[0], box[1], box[2], box[3]
    ulo, uhi, vlo, vhi = bounds[0], bounds[1], bounds[2], bounds[3]
    for by0 in range(ry0, ry1, BLOCK_PX):
        by1 = min(by0 + BLOCK_PX, ry1)
        for bx0 in range(rx0, rx1, BLOCK_PX):
            bx1 = min(bx0 + BLOCK_PX, rx1)
            if bx1 <= x0 or bx0 >= x1 or by1 <= y0 or by0 >= y1:
                val = SURROUND  # no pixel of the block in the box
            elif x0 <= bx0 and bx1 <= x1 and y0 <= by0 and by1 <= y1:
                val = _block_value(nx, ny, bx0, by0, bx1, by1, H, kind, cols, rows,
                                   ulo, uhi, vlo, vhi)  # fmt: skip
            else:
                val = -1.0
            for yy in range(by0, by1):
                for xx in range(bx0, bx1):
                    refl = val
                    if refl < 0.0:
                        if yy < y0 or yy >= y1 or xx < x0 or xx >= x1:
                            refl = SURROUND
                        else:
                            refl = _plate_pixel(nx, ny, yy, xx, H, kind, cols, rows, radius,
                                                ulo, uhi, vlo, vhi)  # fmt: skip
                    lit = _lit(xx, yy, gain, strength, cx, cy, rc2)
                    out[yy - ry0, xx - rx0] = refl * lit


@njit(cache=True)
def plate_image(nx, ny, box, H, kind, cols, rows, radius, bounds, light, out) -> None:
    """:func:`plate_region` over the whole image ``out`` ((h, w) float32, the rays' shape)."""
    h, w = out.shape
    region = np.array([0, 0, w, h], dtype=np.int64)
    plate_region(nx, ny, region, box, H, kind, cols, rows, radius, bounds, light, out)
