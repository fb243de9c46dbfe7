"""Area-integrated reflectance of a calibration plate's pattern at pixels (float32).

The plate coordinates ``(u, v)`` of each pixel centre are given in pitches, shifted by an
even number of pitches (``shift``) so that float32 keeps them exact to ~1e-6 pitch; their
pixel gradients give each edge's normal and the pixel's distance to it, and
:mod:`measure.synth.coverage` integrates the pixel's area across the edge. Exact along every
edge; within a pixel of a chessboard corner the two edges' coverages are multiplied (a
point-symmetric approximation that cannot move the corner). Assumes a pitch of several pixels.
"""

from __future__ import annotations

import numpy as np

from measure.synth.coverage import band_coverage, edge_coverage
from measure.target import TargetSpec

#: reflectance of the black and white print and of what lies around the plate
BLACK, WHITE, SURROUND = 0.08, 0.92, 0.25


def _sides(
    u: np.ndarray, gx: np.ndarray, gy: np.ndarray, lo: float, hi: float
) -> tuple[np.ndarray, np.ndarray]:
    """Coverage of the pixel by "even" squares (``floor(u)`` even) and by "odd" squares, both
    only for ``lo < u < hi`` (integer bounds)."""
    k = np.rint(u)
    g = np.sqrt(gx * gx + gy * gy) + np.float32(1e-12)
    right = edge_coverage((u - k) / g, gx, gy)  # part of the pixel at u > k
    left = 1.0 - right
    even_right = np.remainder(k, 2.0) == 0.0  # the square right of line k is even
    in_right = (k >= lo) & (k < hi)
    in_left = (k > lo) & (k <= hi)
    r = np.where(in_right, right, 0.0)
    l_ = np.where(in_left, left, 0.0)
    even = np.where(even_right, r, l_)
    odd = np.where(even_right, l_, r)
    return even.astype(np.float32, copy=False), odd.astype(np.float32, copy=False)


def chessboard_black(
    spec: TargetSpec, u: np.ndarray, v: np.ndarray, grads: tuple, shift: tuple[int, int]
) -> np.ndarray:
    """Fraction of each pixel covered by black squares (squares span -1 .. cols, -1 .. rows
    pitches; black where ``floor(u) + floor(v)`` is even)."""
    ux, uy, vx, vy = grads
    su, sv = shift
    ue, uo = _sides(u, ux, uy, -1 - su, spec.cols - su)
    ve, vo = _sides(v, vx, vy, -1 - sv, spec.rows - sv)
    return ue * ve + uo * vo


def circles_black(
    spec: TargetSpec, u: np.ndarray, v: np.ndarray, grads: tuple, shift: tuple[int, int]
) -> np.ndarray:
    """Fraction of each pixel covered by the nearest circle of the asymmetric grid (row ``i``
    at v = i, centres at u = 2j + i mod 2; diameter ``circle_diameter_frac`` pitches)."""
    ux, uy, vx, vy = grads
    su, sv = shift
    i = np.clip(np.rint(v + sv), 0, spec.rows - 1)
    odd = np.remainder(i, 2.0)
    j = np.clip(np.rint((u + su - odd) / 2.0), 0, spec.cols - 1)
    du = u - (2.0 * j + odd - su).astype(np.float32)
    dv = v - (i - sv).astype(np.float32)
    r = np.sqrt(du * du + dv * dv) + np.float32(1e-9)
    gx = (du * ux + dv * vx) / r  # gradient of r in pixel coordinates
    gy = (du * uy + dv * vy) / r
    g = np.sqrt(gx * gx + gy * gy) + np.float32(1e-12)
    # the edge's curvature in pixels, kappa = |J tau|^2 / (r |grad r|), tau its unit tangent:
    # over a pixel the disc falls short of its tangent line by kappa <x_t^2> / 2 = kappa / 24
    tx, ty = -gy / g, gx / g
    ju, jv = ux * tx + uy * ty, vx * tx + vy * ty
    kappa = (ju * ju + jv * jv) / (r * g)
    radius = np.float32(0.5 * spec.circle_diameter_frac)
    return 1.0 - edge_coverage((r - radius) / g + kappa / np.float32(24.0), gx, gy)


def _area_reflectance(spec, u, v, grads, shift) -> np.ndarray:
    """Area-integrated reflectance (any pixels)."""
    black_fn = chessboard_black if spec.kind == "chessboard" else circles_black
    black = black_fn(spec, u, v, grads, shift)
    lo, hi = _bounds(spec, shift)
    ux, uy, vx, vy = grads
    on = band_coverage(u, lo[0], hi[0], ux, uy) * band_coverage(v, lo[1], hi[1], vx, vy)
    print_ = np.float32(WHITE) - np.float32(WHITE - BLACK) * black
    return (np.float32(SURROUND) + (print_ - np.float32(SURROUND)) * on).astype(np.float32)


def _bounds(spec: TargetSpec, shift: tuple[int, int]) -> tuple[np.ndarray, np.ndarray]:
    """The plate's (u, v) bounds (pitches, shifted)."""
    lo, hi = spec.plate_bounds()
    sh = np.asarray(shift, dtype=float)
    return lo / spec.pitch_m - sh, hi / spec.pitch_m - sh


def _point_reflectance(spec, u, v, shift) -> np.ndarray:
    """Reflectance at the pixel centres, and where a pixel may straddle an edge."""
    su, sv = shift
    if spec.kind == "chessboard":
        inside = (u > -1 - su) & (u < spec.cols - su) & (v > -1 - sv) & (v < spec.rows - sv)
        black = inside & (np.remainder(np.floor(u) + np.floor(v), 2.0) == 0.0)
    else:
        i = np.clip(np.rint(v + sv), 0, spec.rows - 1)
        odd = np.remainder(i, 2.0)
        j = np.clip(np.rint((u + su - odd) / 2.0), 0, spec.cols - 1)
        du, dv = u - (2.0 * j + odd - su), v - (i - sv)
        black = du * du + dv * dv < np.float32((0.5 * spec.circle_diameter_frac) ** 2)
    lo, hi = _bounds(spec, shift)
    on = (u > lo[0]) & (u < hi[0]) & (v > lo[1]) & (v < hi[1])
    out = np.where(black, np.float32(BLACK), np.float32(WHITE))
    return np.where(on, out, np.float32(SURROUND))


def _near_edges(spec, u, v, grads, shift) -> np.ndarray:
    """Pixels whose area may reach across an edge (within 0.75 px of one)."""
    ux, uy, vx, vy = grads
    m_u = np.float32(0.75) * np.sqrt(ux * ux + uy * uy)
    m_v = np.float32(0.75) * np.sqrt(vx * vx + vy * vy)
    lo, hi = _bounds(spec, shift)
    near = (np.abs(u - lo[0]) < m_u) | (np.abs(u - hi[0]) < m_u)
    near |= (np.abs(v - lo[1]) < m_v) | (np.abs(v - hi[1]) < m_v)
    if spec.kind == "chessboard":
        near |= (np.abs(u - np.rint(u)) < m_u) | (np.abs(v - np.rint(v)) < m_v)
        return near
    su, sv = shift
    i = np.clip(np.rint(v + sv), 0, spec.rows - 1)
    odd = np.remainder(i, 2.0)
    j = np.clip(np.rint((u + su - odd) / 2.0), 0, spec.cols - 1)
    du, dv = u - (2.0 * j + odd - su), v - (i - sv)
    r = np.sqrt(du * du + dv * dv)
    # |grad r| <= max(|grad u|, |grad v|) + ... bounded by the larger of the two margins
    near |= np.abs(r - np.float32(0.5 * spec.circle_diameter_frac)) < np.maximum(m_u, m_v)
    return near


def plate_reflectance(
    spec: TargetSpec, u: np.ndarray, v: np.ndarray, grads: tuple, shift: tuple[int, int]
) -> np.ndarray:
    """Area-integrated reflectance (float32) of pixels with plate coordinates ``u + shift[0]``,
    ``v + shift[1]`` pitches and gradients ``grads = (du/dx, du/dy, dv/dx, dv/dy)``: the
    pixel-centre value, integrated over the area of the pixels near an edge."""
    out = _point_reflectance(spec, u, v, shift)
    near = _near_edges(spec, u, v, grads, shift)
    sub = tuple(g[near] for g in grads)
    out[near] = _area_reflectance(spec, u[near], v[near], sub, shift)
    return out
