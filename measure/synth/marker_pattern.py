"""Area-integrated reflectance of a reference marker at pixels, compiled by Numba.

A marker is a plane: a black label holding a white dot and its code (a ring of sectors, or an
AprilTag beside the dot). Each pixel's marker coordinates ``(u, v)`` (dot diameters, ``u``
along the marker's ``up``) and their pixel gradients give every edge's distance in pixels, and
the pixel's coverage is the exact area integral across straight edges
(:func:`measure.synth.target_pattern.edge_coverage`); circle edges are corrected for their
curvature as on the calibration plate, and where two edges meet (a ring sector's corner, a tag
cell's corner) their coverages are multiplied.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from measure.synth.target_pattern import _band, edge_coverage

RING, APRILTAG = 0, 1


@njit(cache=True)
def _disc(r: float, radius: float, gx: float, gy: float, ju2: float) -> float:
    """Fraction of a pixel inside the circle ``r < radius`` (``(gx, gy)`` = grad r per pixel,
    ``ju2`` = squared plane length of one pixel step along the edge)."""
    g = math.sqrt(gx * gx + gy * gy) + 1e-300
    d = (r - radius) / g
    if d >= 1.0:
        return 0.0
    if d <= -1.0:
        return 1.0
    kappa = ju2 / (max(r, 1e-9) * g)  # the edge's curvature, 1/px
    return 1.0 - edge_coverage(d + kappa / 24.0, gx, gy)


@njit(cache=True)
def _split(c: float, gx: float, gy: float) -> tuple[int, float, float]:
    """A pixel at grid coordinate ``c`` (gradient ``gx, gy`` per pixel) near a grid line: the
    cell index ``k`` above the line, the pixel's fraction in cell ``k`` and in cell ``k - 1``."""
    k = math.floor(c + 0.5)
    g = math.sqrt(gx * gx + gy * gy) + 1e-300
    if abs(c - k) >= g:  # farther than a pixel from the line: one cell
        f = math.floor(c)
        return int(f), 1.0, 0.0
    hi = edge_coverage((c - k) / g, gx, gy)
    return int(k), hi, 1.0 - hi


@njit(cache=True)
def _ring_white(u, v, ux, uy, vx, vy, r, rx, ry, ju2, sectors, r_in, r_out) -> float:
    """Fraction of a pixel on a white sector of the code ring."""
    band = _disc(r, r_out, rx, ry, ju2) - _disc(r, r_in, rx, ry, ju2)
    if band <= 0.0:
        return 0.0
    n = sectors.shape[0]
    step = 2.0 * math.pi / n
    phi = math.atan2(v, u)
    if phi < 0.0:
        phi += 2.0 * math.pi
    k = math.floor(phi / step + 0.5)
    s, c = math.sin(k * step), math.cos(k * step)
    # f: signed distance from the radial line at angle k·step (positive toward sector k)
    f = -s * u + c * v
    gx, gy = -s * ux + c * vx, -s * uy + c * vy
    g = math.sqrt(gx * gx + gy * gy) + 1e-300
    if f >= g:  # a pixel or more from the sector boundary: wholly in one sector
        above = 1.0
    elif f <= -g:
        above = 0.0
    else:
        above = edge_coverage(f / g, gx, gy)
    white = sectors[k % n] * above + sectors[(k - 1) % n] * (1.0 - above)
    return band * white


@njit(cache=True)
def _tag_white(u, v, ux, uy, vx, vy, field, x0, top, cell) -> float:
    """Fraction of a pixel on a white cell of the tag's field (``field`` (m, m), row 0 at
    ``v = top``, column 0 at ``u = x0``; black outside)."""
    m = field.shape[0]
    cc, cr = (u - x0) / cell, (top - v) / cell
    if cc < -1.0 or cr < -1.0 or cc > m + 1.0 or cr > m + 1.0:
        return 0.0
    kc, fc_hi, fc_lo = _split(cc, ux / cell, uy / cell)
    kr, fr_hi, fr_lo = _split(cr, -vx / cell, -vy / cell)
    white = 0.0
    for dc in range(2):
        col, wc = (kc, fc_hi) if dc == 0 else (kc - 1, fc_lo)
        if wc <= 0.0 or col < 0 or col >= m:
            continue
        for dr in range(2):
            row, wr = (kr, fr_hi) if dr == 0 else (kr - 1, fr_lo)
            if wr <= 0.0 or row < 0 or row >= m:
                continue
            white += wc * wr * field[row, col]
    return white


@njit(cache=True)
def _ray(gnx, gny, gx0, gy0, step, px, py) -> tuple[float, float, float, float, float, float]:
    """Bilinear ray ``(nx, ny)`` at pixel ``(px, py)`` from grid nodes at ``gx0 + i step``,
    and its pixel derivatives ``d(nx, ny)/dx``, ``d(nx, ny)/dy`` within the grid cell."""
    fx, fy = (px - gx0) / step, (py - gy0) / step
    rows, cols = gnx.shape
    ix = min(max(math.floor(fx), 0), cols - 2)
    iy = min(max(math.floor(fy), 0), rows - 2)
    ax, ay = fx - ix, fy - iy
    a00, a01, a10, a11 = gnx[iy, ix], gnx[iy, ix + 1], gnx[iy + 1, ix], gnx[iy + 1, ix + 1]
    b00, b01, b10, b11 = gny[iy, ix], gny[iy, ix + 1], gny[iy + 1, ix], gny[iy + 1, ix + 1]
    x = (a00 * (1 - ax) + a01 * ax) * (1 - ay) + (a10 * (1 - ax) + a11 * ax) * ay
    y = (b00 * (1 - ax) + b01 * ax) * (1 - ay) + (b10 * (1 - ax) + b11 * ax) * ay
    x_x = ((a01 - a00) * (1 - ay) + (a11 - a10) * ay) / step
    y_x = ((b01 - b00) * (1 - ay) + (b11 - b10) * ay) / step
    x_y = ((a10 - a00) * (1 - ax) + (a11 - a01) * ax) / step
    y_y = ((b10 - b00) * (1 - ax) + (b11 - b01) * ax) / step
    return x, y, x_x, y_x, x_y, y_y


@njit(cache=True, inline="always")
def _uv(gnx, gny, gx0, gy0, step, H, px, py):
    """``(den, u, v, ux, uy, vx, vy)`` at pixel ``(px, py)``: the homography's denominator
    (``<= 0``: the ray misses the marker's face), the marker coordinates and their pixel
    gradients."""
    x, y, rx_x, ry_x, rx_y, ry_y = _ray(gnx, gny, gx0, gy0, step, px, py)
    den = H[2, 0] * x + H[2, 1] * y + H[2, 2]
    if den <= 0.0:
        return den, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    u = (H[0, 0] * x + H[0, 1] * y + H[0, 2]) / den
    v = (H[1, 0] * x + H[1, 1] * y + H[1, 2]) / den
    au, bu = (H[0, 0] - u * H[2, 0]) / den, (H[0, 1] - u * H[2, 1]) / den
    av, bv = (H[1, 0] - v * H[2, 0]) / den, (H[1, 1] - v * H[2, 1]) / den
    ux, uy = au * rx_x + bu * ry_x, au * rx_y + bu * ry_y
    vx, vy = av * rx_x + bv * ry_x, av * rx_y + bv * ry_y
    return den, u, v, ux, uy, vx, vy


#: side (px) of the blocks a ring marker is drawn in: the ray grid's cells (its rays are
#: bilinear within one), so a block's marker coordinates are their corners' to ~0.01 px
RING_BLOCK_PX = 8
#: a block takes one value when its corners keep every pixel this many times the largest
#: corner gradient (px) clear of every edge (each pixel's own test asks for 1 px of its own)
RING_BLOCK_CLEAR = 1.75
#: boxes smaller than this (px a side) are drawn pixel by pixel: their edges leave few blocks
#: clear (a 5 mm dot at 1 m spans 23 px)
RING_BLOCKS_FROM_PX = 120
#: what a block's value says besides a white fraction: leave it as it is, draw it pixel by pixel
OUTSIDE, PER_PIXEL = -1.0, -2.0


@njit(cache=True)
def _ring_block(gnx, gny, gx0, gy0, step, box, H, geo, sectors, bx0, by0, bx1, by1) -> float:
    """The white fraction (0 or 1) every pixel of the block ``[bx0, bx1) x [by0, by1)`` (box
    pixels) of a ring marker has when its corners put them all well clear of every circle and
    sector edge (in the dot, on the black label, inside one sector), :data:`OUTSIDE` when all
    lie well outside the label, else :data:`PER_PIXEL`."""
    umin, umax, vmin, vmax = math.inf, -math.inf, math.inf, -math.inf
    g_lo, g_hi, rmax = math.inf, 0.0, 0.0
    us, vs = np.empty(4), np.empty(4)
    for k in range(4):
        xx = bx0 if k % 2 == 0 else bx1 - 1
        yy = by0 if k < 2 else by1 - 1
        den, u, v, ux, uy, vx, vy = _uv(gnx, gny, gx0, gy0, step, H, float(box[0] + xx),
                                        float(box[1] + yy))  # fmt: skip
        if den <= 0.0:
            return PER_PIXEL
        us[k], vs[k] = u, v
        umin, umax, vmin, vmax = min(umin, u), max(umax, u), min(vmin, v), max(vmax, v)
        rmax = max(rmax, math.sqrt(u * u + v * v))
        g = math.sqrt(ux * ux + uy * uy + vx * vx + vy * vy)  # bounds |grad r|, |grad f|
        g_lo, g_hi = min(g_lo, g), max(g_hi, g)
    if g_hi > 1.25 * g_lo:
        return PER_PIXEL
    d = RING_BLOCK_CLEAR * g_hi
    du = 0.0 if umin <= 0.0 <= umax else min(abs(umin), abs(umax))
    dv = 0.0 if vmin <= 0.0 <= vmax else min(abs(vmin), abs(vmax))
    r0, r1 = math.sqrt(du * du + dv * dv) - d, rmax + d  # every pixel's r lies within
    if r0 >= geo[2]:
        return OUTSIDE
    for edge in (0.5, geo[0], geo[1], geo[2]):
        if r0 <= edge <= r1:
            return PER_PIXEL
    if r1 < 0.5:
        return 1.0  # the dot
    if r1 < geo[0] or r0 > geo[1]:
        return 0.0  # the black label, inside or outside the ring
    n = sectors.shape[0]
    step_a = 2.0 * math.pi / n
    phi = math.atan2(vs[0], us[0])
    if phi < 0.0:
        phi += 2.0 * math.pi
    j = math.floor(phi / step_a)
    for b in range(2):  # the sector's two boundaries, as the pixel test computes them
        s, c = math.sin((j + b) * step_a), math.cos((j + b) * step_a)
        for k in range(4):
            f = -s * us[k] + c * vs[k]
            if (b == 0 and f < d) or (b == 1 and f > -d):
                return PER_PIXEL
    return sectors[int(j) % n]  # inside one sector


@njit(cache=True)
def marker_patch(
    grid, gx0, gy0, step, box, H, kind, geo, sectors, field, levels, lit, out, spans, blocks=True
):
    """Draw one marker into ``out`` ((h, w) float32: the pixels ``box`` = (x0, y0) onward,
    holding what lies behind the marker).

    ``grid`` (2, rows, cols): exact rays ``(nx, ny)`` at pixel nodes ``(gx0 + i step, gy0 + j
    step)``, interpolated bilinearly; ``H`` maps a ray to homogeneous marker coordinates (dot
    diameters); rays with ``H[2] . d <= 0`` miss the marker's face. ``geo``: ring ``(r_in,
    r_out, label_radius)``, tag ``(x_lo, x_hi, y_lo, y_hi, field_x0, field_top, cell)``.
    ``levels`` = (black, white) reflectance; ``lit`` ((h, w)): illumination. ``spans`` (h, 2):
    per row the columns ``[lo, hi)`` that can touch the label (the rest are left as they are).
    A ring is drawn in blocks (:func:`_ring_block`; ``blocks``, on a grid of ``RING_BLOCK_PX``
    nodes and a box of ``RING_BLOCKS_FROM_PX`` or more): a block clear of every edge takes the
    value each of its pixels would get (the same image, bit for bit).
    """
    h, w = out.shape
    gnx, gny = grid[0], grid[1]
    black, white_level = levels[0], levels[1]
    blocks = blocks and kind == RING and step == RING_BLOCK_PX and min(h, w) >= RING_BLOCKS_FROM_PX
    B = RING_BLOCK_PX
    vals = np.full((w + B - 1) // B, PER_PIXEL)
    for yy in range(h):
        if blocks and yy % B == 0:  # a new row of blocks
            by1 = min(yy + B, h)
            lo, hi = spans[yy:by1, 0].min(), spans[yy:by1, 1].max()
            for k in range(vals.shape[0]):
                bx0, bx1 = k * B, min(k * B + B, w)
                vals[k] = PER_PIXEL
                if bx1 > lo and bx0 < hi:
                    vals[k] = _ring_block(gnx, gny, gx0, gy0, step, box, H, geo, sectors,
                                          bx0, yy, bx1, by1)  # fmt: skip
        for xx in range(spans[yy, 0], spans[yy, 1]):
            val = vals[xx // B]
            if val != PER_PIXEL:
                if val != OUTSIDE:
                    out[yy, xx] = (black * (1.0 - val) + white_level * val) * lit[yy, xx]
                continue
            den, u, v, ux, uy, vx, vy = _uv(
                gnx, gny, gx0, gy0, step, H, float(box[0] + xx), float(box[1] + yy)
            )
            if den <= 0.0:
                continue
            r = math.sqrt(u * u + v * v) + 1e-12
            rx, ry = (u * ux + v * vx) / r, (u * uy + v * vy) / r  # grad r, per pixel
            g = math.sqrt(rx * rx + ry * ry) + 1e-300
            if kind == RING:
                if r - geo[2] >= g:
                    continue  # a pixel or more outside the label
                near = min(abs(r - 0.5), abs(r - geo[0]), abs(r - geo[1]), abs(r - geo[2])) < g
                if not near:  # no circle edge within a pixel: only sector boundaries
                    label = 1.0
                    wc = 1.0 if r < 0.5 else 0.0
                    if geo[0] < r < geo[1]:
                        wc = _ring_white(
                            u, v, ux, uy, vx, vy, r, rx, ry, 0.0, sectors, geo[0], geo[1]
                        )
                    refl = black * (label - wc) + white_level * wc
                    out[yy, xx] = refl * lit[yy, xx]
                    continue
            tx, ty = -ry / g, rx / g  # unit tangent of the circle through the pixel
            ju, jv = ux * tx + uy * ty, vx * tx + vy * ty
            ju2 = ju * ju + jv * jv
            if kind == RING:
                label = _disc(r, geo[2], rx, ry, ju2)
                if label <= 0.0:
                    continue
                wc = _disc(r, 0.5, rx, ry, ju2)
                if wc < 1.0 and r > geo[0] - g:
                    wc += _ring_white(u, v, ux, uy, vx, vy, r, rx, ry, ju2, sectors, geo[0], geo[1])
            else:
                label = _band(u, geo[0], geo[1], ux, uy) * _band(v, geo[2], geo[3], vx, vy)
                if label <= 0.0:
                    continue
                wc = _disc(r, 0.5, rx, ry, ju2)
                if wc < 1.0 and u > geo[4] - 2.0 * math.sqrt(ux * ux + uy * uy):
                    wc += _tag_white(u, v, ux, uy, vx, vy, field, geo[4], geo[5], geo[6])
            refl = black * (label - wc) + white_level * wc
            out[yy, xx] = out[yy, xx] * (1.0 - label) + refl * lit[yy, xx]
