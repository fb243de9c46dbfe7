"""Datum reference frames and best-fit alignments from measured hole centres.

Everything is vectorised over draws: a centre is an array ``(N, 3)`` (N Monte Carlo draws, or
N = 1 for the estimate or the nominal), in the nominal part frame (m). A frame is returned as
``R (N, 3, 3)``, ``t (N, 3)``: ``T_part_drf`` (the DRF's axes and origin in the part frame),
with the RMS residual of each datum feature's fit ``(N,)`` (m).

Construction (3-2-1, docs/gdt.md):

- primary **plane**: least-squares plane through the centres of its holes (orthogonal
  regression, SVD); its normal is the DRF's z, oriented like the holes' mean nominal normal;
  constrains z and the two tilts (3 DOF);
- secondary **hole**: its centre projected onto the primary plane is the origin (2 DOF);
- tertiary **hole**: the direction from the origin to its centre, projected onto the plane,
  is the DRF's x (1 DOF);
- secondary **pattern**: its centres projected onto the plane, origin at their centroid, x
  turned to the least-squares fit of the nominal pattern (2D Procrustes; 3 DOF);
- **pattern** alone or a **best fit**: the least-squares rigid fit of the nominal centres to
  the measured ones (Kabsch), or the minimax fit (the largest distance smallest); 6 DOF;
- **rps**: the six locked coordinates of the RPS points equal their nominals (Gauss-Newton).

For the last two kinds the nominal DRF is the part frame itself.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
from scipy.optimize import minimize

from cell.config.datums import Datum
from cell.gdt.errors import GdtError
from robots.transforms import kabsch, skew, so3_exp

AXIS_INDEX = {"x": 0, "y": 1, "z": 2}


@dataclass(frozen=True)
class Frames:
    """``T_part_drf`` per draw: rotations ``R (N, 3, 3)``, origins ``t (N, 3)`` (m), and the
    RMS residual of each datum feature's fit per draw (label -> ``(N,)``, m)."""

    R: np.ndarray
    t: np.ndarray
    residuals_m: dict[str, np.ndarray]

    def matrix(self, i: int = 0) -> np.ndarray:
        """The 4x4 ``T_part_drf`` of draw ``i``."""
        T = np.eye(4)
        T[:3, :3], T[:3, 3] = self.R[i], self.t[i]
        return T

    def to_drf(self, p_part: np.ndarray) -> np.ndarray:
        """Points ``(N, 3)`` of the part frame into the DRF of each draw (m)."""
        return np.einsum("nji,nj->ni", self.R, p_part - self.t)


def _unit(v: np.ndarray) -> np.ndarray:
    n = np.linalg.norm(v, axis=-1, keepdims=True)
    return v / n


def _plane(pts: np.ndarray, ref_normal: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Least-squares plane of ``pts (N, k, 3)``: unit normal ``(N, 3)`` oriented along
    ``ref_normal``, centroid ``(N, 3)``, RMS distance ``(N,)``."""
    c = pts.mean(axis=1)
    X = pts - c[:, None, :]
    _, s, vt = np.linalg.svd(X)
    n = vt[:, -1, :]
    n = n * np.where(n @ ref_normal < 0, -1.0, 1.0)[:, None]
    if np.any(s[:, 1] < 1e-9 * np.maximum(s[:, 0], 1e-300)):
        raise GdtError("plane", "its holes are collinear: no plane through them")
    rms = np.sqrt(np.mean(np.einsum("nkj,nj->nk", X, n) ** 2, axis=1))
    return n, c, rms


def _project(p: np.ndarray, z: np.ndarray, p0: np.ndarray) -> np.ndarray:
    """Points ``(N, 3)`` projected along ``z`` onto the plane through ``p0``."""
    return p - np.einsum("ni,ni->n", p - p0, z)[:, None] * z


def _basis(z: np.ndarray, x_dir: np.ndarray) -> np.ndarray:
    """Rotations ``(N, 3, 3)`` with columns x, y, z: x is ``x_dir`` made perpendicular to z."""
    x = x_dir - np.einsum("ni,ni->n", x_dir, z)[:, None] * z
    norm = np.linalg.norm(x, axis=1)
    if np.any(norm < 1e-9):
        raise GdtError("tertiary datum", "lies on the normal of the primary through the origin")
    x = x / norm[:, None]
    return np.stack([x, np.cross(z, x), z], axis=2)


def _minimax_step(P: np.ndarray, Q: np.ndarray, R: np.ndarray, t: np.ndarray) -> np.ndarray:
    """The small motion (rotation vector, translation; 6) from (R, t) that makes the largest
    distance of ``Q (k, 3)`` from ``R P + t`` smallest (linearised, SLSQP on the epigraph)."""
    a = P @ R.T
    b = Q - a - t
    scale = max(float(np.abs(b).max()), 1e-12)
    lever = max(float(np.linalg.norm(a - a.mean(0), axis=1).max()), 1e-3)
    b_s = b / scale

    def dist2(x: np.ndarray) -> np.ndarray:
        e = b_s - np.cross(x[:3] / lever, a) - x[3:6]
        return np.sum(e**2, axis=1)

    x0 = np.r_[np.zeros(6), np.sqrt(dist2(np.zeros(7)).max())]
    cons = [{"type": "ineq", "fun": lambda x: x[6] ** 2 - dist2(x)}]
    sol = minimize(lambda x: x[6], x0, method="SLSQP", constraints=cons,
                   options={"maxiter": 200, "ftol": 1e-14})  # fmt: skip
    return np.r_[sol.x[:3] * scale / lever, sol.x[3:6] * scale]


def _worst(P: np.ndarray, Q: np.ndarray, R: np.ndarray, t: np.ndarray) -> float:
    """The largest distance of ``Q (k, 3)`` from ``R P + t`` (m)."""
    return float(np.sqrt(np.max(np.sum((Q - P @ R.T - t) ** 2, axis=1))))


def minimax(P: np.ndarray, Q: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Minimax rigid fit (the largest distance |R P + t - Q| smallest), started from the
    least-squares one (two linearised steps); R, t and the largest distance per draw (m)."""
    R, t, _ = kabsch(P, Q)
    worst = np.empty(len(Q))
    for n in range(len(Q)):
        worst[n] = _worst(P, Q[n], R[n], t[n])
        for _ in range(2):
            if worst[n] < 1e-12:
                break
            x = _minimax_step(P, Q[n], R[n], t[n])
            R1, t1 = so3_exp(x[None, :3])[0] @ R[n], t[n] + x[3:6]
            w1 = _worst(P, Q[n], R1, t1)
            if w1 >= worst[n]:  # a linearised step that does not help is not taken
                break
            R[n], t[n], worst[n] = R1, t1, w1
    return R, t, worst


def rps_frame(
    points: Sequence[tuple[str, Sequence[str]]],
    nominal: Mapping[str, np.ndarray],
    centres: Mapping[str, np.ndarray],
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The placement at which each RPS point's locked coordinates equal its nominal ones
    (Gauss-Newton on six equations); R, t and the RMS of the locked residuals (m)."""  # fmt: skip
    rows = [(h, AXIS_INDEX[a]) for h, axes in points for a in dict.fromkeys(axes)]
    C = np.stack([centres[h] for h, _ in rows], axis=1)  # (N, 6, 3)
    target = np.array([nominal[h][a] for h, a in rows])
    idx = np.array([a for _, a in rows])
    N = C.shape[0]
    R, t = np.repeat(np.eye(3)[None], N, 0), np.zeros((N, 3))
    for _ in range(6):
        d = C - t[:, None, :]
        p = np.einsum("nji,nkj->nki", R, d)  # DRF coordinates
        E = np.eye(3)[idx]  # (6, 3)
        ER = np.einsum("kj,nij->nki", E, R)  # rows e_a^T R^T
        J = np.concatenate([np.einsum("nki,nkij->nkj", ER, skew(d)), -ER], axis=2)
        r = target - p[:, np.arange(len(rows)), idx]
        if np.any(np.abs(np.linalg.det(J)) < 1e-12):
            raise GdtError("rps", "the RPS points do not fix the part (singular set of axes)")
        x = np.linalg.solve(J, r[..., None])[..., 0]
        R = so3_exp(x[:, :3]) @ R
        t = t + x[:, 3:]
    p = np.einsum("nji,nkj->nki", R, C - t[:, None, :])
    res = target - p[:, np.arange(len(rows)), idx]
    return R, t, np.sqrt(np.mean(res**2, axis=1))


def datum_frame(
    datums: Sequence[Datum],
    centres: Mapping[str, np.ndarray],
    nominal: Mapping[str, np.ndarray],
    normals: Mapping[str, np.ndarray],
) -> Frames:
    """``T_part_drf`` of the datums in precedence from ``centres`` (hole id -> ``(N, 3)``, m);
    ``nominal`` (hole id -> ``(3,)``) serves the pattern and RPS fits, ``normals`` (nominal
    unit axes) orient a plane. Pass the nominal centres as ``centres`` for the nominal
    DRF."""
    kinds = tuple(d.kind for d in datums)
    first = datums[0]
    if kinds == ("rps",):
        R, t, res = rps_frame([(p.hole, p.axes) for p in first.rps or []], nominal, centres)
        return Frames(R, t, {first.label: res})
    if kinds == ("pattern",):
        ids = first.hole_ids()
        R, t, res = kabsch(np.stack([nominal[h] for h in ids]),
                           np.stack([centres[h] for h in ids], axis=1))  # fmt: skip
        return Frames(R, t, {first.label: res})
    ids = first.hole_ids()
    ref = _unit(np.mean([normals[h] for h in ids], axis=0))
    z, p0, res_a = _plane(np.stack([centres[h] for h in ids], axis=1), ref)
    second = datums[1]
    residuals = {first.label: res_a}
    if second.kind == "pattern":
        nz, np0, _ = _plane(np.stack([nominal[h] for h in ids])[None], ref)
        origin, x, residuals[second.label] = _pattern_in_plane(
            second.hole_ids(), centres, nominal, (z, p0), (nz, np0)
        )
        return Frames(_basis(z, x), origin, residuals)
    origin = _project(centres[second.hole], z, p0)
    residuals[second.label] = np.zeros(len(z))
    third = datums[2]
    R = _basis(z, centres[third.hole] - origin)
    residuals[third.label] = np.zeros(len(z))
    return Frames(R, origin, residuals)


def _pattern_2d(
    ids: Sequence[str], pts: Mapping[str, np.ndarray], z: np.ndarray, p0: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A pattern projected onto a plane: centroid ``(N, 3)``, a provisional basis ``(N, 3,
    3)`` (x towards the first hole) and the 2D coordinates in it ``(N, k, 2)``."""
    proj = np.stack([_project(pts[h], z, p0) for h in ids], axis=1)
    origin = proj.mean(axis=1)
    B = _basis(z, proj[:, 0, :] - origin)
    return origin, B, np.einsum("nji,nkj->nki", B, proj - origin[:, None, :])[..., :2]


def _pattern_in_plane(ids, centres, nominal, plane, nominal_plane):
    """Origin ``(N, 3)``, x axis ``(N, 3)`` and RMS residual ``(N,)`` of a secondary pattern:
    the nominal pattern (in its nominal frame) turned onto the measured one (2D Procrustes)."""
    origin, B, q = _pattern_2d(ids, centres, *plane)
    nominal_n = {h: np.asarray(nominal[h], float)[None] for h in ids}
    _, _, qn = _pattern_2d(ids, nominal_n, *nominal_plane)
    qn = qn[0]
    dot = np.einsum("ki,nki->n", qn, q)
    crs = np.einsum("k,nk->n", qn[:, 0], q[..., 1]) - np.einsum("k,nk->n", qn[:, 1], q[..., 0])
    th = np.arctan2(crs, dot)
    c, s = np.cos(th), np.sin(th)
    x = c[:, None] * B[:, :, 0] + s[:, None] * B[:, :, 1]
    fit = np.stack([c[:, None] * qn[:, 0] - s[:, None] * qn[:, 1],
                    s[:, None] * qn[:, 0] + c[:, None] * qn[:, 1]], axis=2)  # fmt: skip
    return origin, x, np.sqrt(np.mean(np.sum((fit - q) ** 2, axis=2), axis=1))


def best_fit_frame(
    ids: Sequence[str],
    centres: Mapping[str, np.ndarray],
    nominal: Mapping[str, np.ndarray],
    method: str,
) -> Frames:
    """The best-fit placement over holes ``ids`` (least squares or minimax) as a frame."""
    P = np.stack([nominal[h] for h in ids])
    Q = np.stack([centres[h] for h in ids], axis=1)
    R, t, res = (minimax if method == "minimax" else kabsch)(P, Q)
    return Frames(R, t, {"best_fit": res})
