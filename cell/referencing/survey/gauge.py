"""The survey's gauge: the marker network is moved (rigidly, no scale) onto the nominal
positions of its gauge markers by least squares, and its covariance is S-transformed into that
gauge, so neither depends on the solvers' temporary datum (view 0 held).

Gauge markers: the fixture's (``on: fixture``, nominal in the cell frame: they do not move with
the part), when at least three of them span a plane; else every marker (the part's nominal
placement then defines the frame). ``S = I - G (G_g^T G_g)^-1 G_g^T`` with ``G`` (3n, 6) the
network's rigid motions (translation and small rotation about the gauge markers' centroid)
and ``G_g`` its gauge rows; the covariance in the gauge is ``S C S^T``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from robots.transforms import kabsch, make_transform, skew

Array = NDArray[np.float64]


@dataclass(frozen=True)
class Gauged:
    """Marker centres (n, 3) m and joint covariance (3n, 3n) m² in the gauge; ``T_gauge_solver``
    the rigid move applied; ``kind``: ``"fixture markers"`` or ``"all markers"``;
    ``residuals_m``: the gauge markers' distances from their nominal positions after the fit."""

    points: Array
    covariance: Array | None
    T_gauge_solver: Array
    kind: str
    gauge_rows: NDArray[np.int64]
    residuals_m: Array


def rigid_fit(P: Array, Q: Array) -> Array:
    """The rigid transform (4, 4) minimising ``sum |T P_i - Q_i|^2``
    (:func:`robots.transforms.kabsch`)."""
    R, t, _ = kabsch(P, np.asarray(Q, float)[None])
    return make_transform(R[0], t[0])


def gauge_rows(on_fixture: NDArray[np.bool_], nominal: Array) -> tuple[NDArray[np.int64], str]:
    """The rows that define the gauge (module doc)."""
    rows = np.flatnonzero(on_fixture)
    if len(rows) >= 3:
        sv = np.linalg.svd(nominal[rows] - nominal[rows].mean(axis=0), compute_uv=False)
        if sv[1] > 1e-3 * sv[0] + 1e-6:
            return rows, "fixture markers"
    return np.arange(len(nominal)), "all markers"


def to_gauge(
    points: Array, covariance: Array | None, nominal: Array, on_fixture: NDArray[np.bool_]
) -> Gauged:
    """Move ``points`` (solver datum) onto the gauge markers' ``nominal`` positions."""
    rows, kind = gauge_rows(on_fixture, nominal)
    T = rigid_fit(points[rows], nominal[rows])
    moved = points @ T[:3, :3].T + T[:3, 3]
    cov = None
    if covariance is not None:
        R = np.kron(np.eye(len(points)), T[:3, :3])
        C = R @ covariance @ R.T
        c = moved[rows].mean(axis=0)
        G = np.hstack([np.tile(np.eye(3), (len(points), 1)), -skew(moved - c).reshape(-1, 3)])
        idx = (3 * rows[:, None] + np.arange(3)).ravel()
        Gg = G[idx]
        S = np.eye(3 * len(points))
        S[:, idx] -= G @ np.linalg.solve(Gg.T @ Gg, Gg.T)
        cov = S @ C @ S.T
        cov = 0.5 * (cov + cov.T)
    res = np.linalg.norm(moved[rows] - nominal[rows], axis=1)
    return Gauged(moved, cov, T, kind, rows, res)
