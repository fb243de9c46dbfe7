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


@njit(cache=True)
def rim_view_angles_max(points, center, normal, cameras):
    """Per point (N, 3), the largest rim view angle (rad) over the camera centres (K, 3)
    (:func:`measure.nearside.rim_view_angles`, whose maximum over the cameras the near-side
    check needs): one pass instead of a dozen array operations per camera."""
    nx, ny, nz = normal[0], normal[1], normal[2]
    out = np.empty(points.shape[0])
    for i in range(points.shape[0]):
        px, py, pz = points[i, 0], points[i, 1], points[i, 2]
        dx, dy, dz = px - center[0], py - center[1], pz - center[2]
        h = dx * nx + dy * ny + dz * nz
        rx, ry, rz = dx - h * nx, dy - h * ny, dz - h * nz
        nr = max(np.sqrt(rx * rx + ry * ry + rz * rz), 1e-300)
        rx, ry, rz = rx / nr, ry / nr, rz / nr
        best = -np.inf
        for k in range(cameras.shape[0]):
            sx, sy, sz = cameras[k, 0] - px, cameras[k, 1] - py, cameras[k, 2] - pz
            a = np.arctan2(sx * rx + sy * ry + sz * rz, sx * nx + sy * ny + sz * nz)
            best = max(best, a)
        out[i] = best
    return out


@njit(cache=True)
def basis(n):
    """Two unit vectors u = n × ref / |…| and v = n × u completing the unit normal ``n``
    (ref: the x axis, else the y axis), as :func:`measure.circle._basis`."""
    x, y, z = n[0], n[1], n[2]
    if abs(x) < 0.9:
        u0, u1, u2 = 0.0, z, -y
    else:
        u0, u1, u2 = -z, 0.0, x
    k = 1.0 / np.sqrt(u0 * u0 + u1 * u1 + u2 * u2)
    u0, u1, u2 = u0 * k, u1 * k, u2 * k
    u = np.array([u0, u1, u2])
    v = np.array([y * u2 - z * u1, z * u0 - x * u2, x * u1 - y * u0])
    return u, v


@njit(cache=True)
def solve_small(M, b):
    """x with M x = b for a small dense M (LU with partial pivoting, as LAPACK's dgesv);
    ``ok`` is False when a pivot is exactly zero (singular)."""
    m = M.shape[0]
    a = M.copy()
    x = b.copy()
    for j in range(m):
        p = j
        for i in range(j + 1, m):
            if abs(a[i, j]) > abs(a[p, j]):
                p = i
        if a[p, j] == 0.0:
            return x, False
        if p != j:
            for k in range(m):
                a[j, k], a[p, k] = a[p, k], a[j, k]
            x[j], x[p] = x[p], x[j]
        for i in range(j + 1, m):
            f = a[i, j] / a[j, j]
            for k in range(j + 1, m):
                a[i, k] -= f * a[j, k]
            x[i] -= f * x[j]
    for j in range(m - 1, -1, -1):
        s = x[j]
        for k in range(j + 1, m):
            s -= a[j, k] * x[k]
        x[j] = s / a[j, j]
    return x, True


@njit(cache=True)
def lm_orthogonal(pts, sw, c, n, r, max_iter):
    """Levenberg–Marquardt on the orthogonal cost, the whole loop compiled (the Python
    loop's small-array operations were most of the fit's time); see
    :func:`measure.circle._lm_orthogonal` for the method and the stopping rule.
    Returns centre, normal, radius, JᵀJ at the end and the cost eᵀe."""
    u, v = basis(n)
    A, g, cost = orthogonal_system(pts, sw, c, n, u, v, r)
    lam = 1e-6
    for _ in range(max_iter):
        M = A.copy()
        for i in range(6):
            M[i, i] += lam * max(A[i, i], 1e-300)
        step, ok = solve_small(M, -g)
        if not ok:
            break
        sg = 0.0
        sas = 0.0
        big = 0.0
        for i in range(6):
            sg += step[i] * g[i]
            big = max(big, abs(step[i]))
            for k in range(6):
                sas += step[i] * A[i, k] * step[k]
        predicted = -(2.0 * sg + sas)  # cost decrease of the linear model
        if predicted <= 1e-10 * cost or big <= 1e-10 * abs(r):
            break  # converged: what is left is rounding
        nn = n + step[3] * u + step[4] * v
        nn /= np.sqrt(nn[0] * nn[0] + nn[1] * nn[1] + nn[2] * nn[2])
        cc = c + step[:3]
        rr = r + step[5]
        u2, v2 = basis(nn)
        A2, g2, cost2 = orthogonal_system(pts, sw, cc, nn, u2, v2, rr)
        if cost2 < cost:
            c, n, r, A, g, cost, u, v = cc, nn, rr, A2, g2, cost2, u2, v2
            lam = max(lam * 0.1, 1e-12)
        else:
            lam *= 10.0
    return c, n, r, A, cost


@njit(cache=True)
def _median(a):
    """``np.median`` of a short 1-D array (sorted in place by insertion; the mean of the
    two middle values when even, as NumPy): compiles in a fraction of numba's median."""
    n = a.shape[0]
    for k in range(1, n):
        v = a[k]
        m = k - 1
        while m >= 0 and a[m] > v:
            a[m + 1] = a[m]
            m -= 1
        a[m + 1] = v
    h = n // 2
    return a[h] if n % 2 else (a[h - 1] + a[h]) / 2.0


@njit(cache=True)
def off_sectors(h, dr, sector, mask, min_points, limit):
    """Points of ``mask`` in sectors (integer labels ``sector``) with at least
    ``min_points`` of them whose median residual vector (median h, median ρ − r) is longer
    than ``limit`` (:func:`measure.nearside._off_sectors`, one median pair per sector)."""
    n = h.shape[0]
    out = np.zeros(n, np.bool_)
    lo, hi = 1 << 30, -(1 << 30)
    for i in range(n):
        if mask[i]:
            lo, hi = min(lo, sector[i]), max(hi, sector[i])
    hs = np.empty(n)
    ds = np.empty(n)
    for b in range(lo, hi + 1):
        m = 0
        for i in range(n):
            if mask[i] and sector[i] == b:
                hs[m], ds[m] = h[i], dr[i]
                m += 1
        if m < min_points:
            continue
        if np.hypot(_median(hs[:m]), _median(ds[:m])) > limit:
            for i in range(n):
                if mask[i] and sector[i] == b:
                    out[i] = True
    return out
