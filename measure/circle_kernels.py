"""Compiled loops of the spatial circle fit (:mod:`measure.circle`): one pass over the points.

The orthogonal-cost Levenberg–Marquardt step needs JᵀJ (6 × 6), Jᵀe and eᵀe of the 2N
residuals (h, ρ − r); in NumPy that is some twenty array passes and temporaries per step,
here one loop that accumulates them (the profile of ``benchmarks/measure_speed.py`` had
the fit at 2–3 ms a pair, most of it in these passes). Compiled on first use and cached
beside this file (``cache=True``). A test checks them against the NumPy expressions.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def orthogonal_system(pts, sw, c, n, u, v, r):
    """JᵀJ, Jᵀe and eᵀe of the weighted residuals (h, ρ − r) per point, with respect to
    (c, a, b, r), the normal moved to n + a u + b v and renormalised, at a = b = 0.

    ``pts`` (N, 3) and ``c`` in one length unit, ``sw`` the square roots of the weights,
    ``n, u, v`` an orthonormal frame (n the circle's normal).
    """
    A = np.zeros((6, 6))
    g = np.zeros(6)
    ee = 0.0
    jh = np.zeros(6)
    jr = np.zeros(6)
    for i in range(pts.shape[0]):
        dx, dy, dz = pts[i, 0] - c[0], pts[i, 1] - c[1], pts[i, 2] - c[2]
        h = dx * n[0] + dy * n[1] + dz * n[2]
        qx, qy, qz = dx - h * n[0], dy - h * n[1], dz - h * n[2]
        rho = max(np.sqrt(qx * qx + qy * qy + qz * qz), 1e-300)
        du = dx * u[0] + dy * u[1] + dz * u[2]
        dv = dx * v[0] + dy * v[1] + dz * v[2]
        w = sw[i]
        eh, er = h * w, (rho - r) * w
        s = w / rho
        jh[0], jh[1], jh[2] = -n[0] * w, -n[1] * w, -n[2] * w
        jh[3], jh[4], jh[5] = du * w, dv * w, 0.0
        jr[0], jr[1], jr[2] = -qx * s, -qy * s, -qz * s
        jr[3], jr[4], jr[5] = -h * du * s, -h * dv * s, -w
        for a in range(6):
            g[a] += jh[a] * eh + jr[a] * er
            for b in range(a, 6):
                A[a, b] += jh[a] * jh[b] + jr[a] * jr[b]
        ee += eh * eh + er * er
    for a in range(6):
        for b in range(a):
            A[a, b] = A[b, a]
    return A, g, ee


@njit(cache=True)
def orthogonal_distances(pts, c, n, r):
    """Distance of each point (N, 3) from the circle (centre ``c``, unit normal ``n``,
    radius ``r``): √(h² + (ρ − r)²)."""
    out = np.empty(pts.shape[0])
    for i in range(pts.shape[0]):
        dx, dy, dz = pts[i, 0] - c[0], pts[i, 1] - c[1], pts[i, 2] - c[2]
        h = dx * n[0] + dy * n[1] + dz * n[2]
        rho = np.sqrt(max(dx * dx + dy * dy + dz * dz - h * h, 0.0))
        out[i] = np.sqrt(h * h + (rho - r) * (rho - r))
    return out
