"""Choosing calibration views: a geometric pre-selection, then an information-based design.

**Geometric pre-selection** (:func:`preselect`), greedy. Its score of a set ``S`` of views is the
sum of three shares in [0, 1], and each step adds the next view's *separation*, its smallest
rotation from a chosen view over ``SEPARATION_RAD`` (at most 1: a view whose orientation was
already chosen, from another arm geometry or distance, adds no rotation):

- *rotations*: the hand-eye's translation is fixed, in the linear (Tsai-Lenz) step, by
  ``(R_ij - I) t_X = ...`` for each pair of stations ``i, j`` with relative tool rotation
  ``R_ij``, so its information is ``M = sum_{i<j} (R_ij - I)^T (R_ij - I)`` with
  ``(R - I)^T (R - I) = 2 (1 - cos θ) (I - a a^T)`` for a rotation θ about ``a``: ``M`` grows with
  large rotations and is singular when every axis is parallel. The share is the mean of the
  geometric and the arithmetic mean of the eigenvalues of ``M / n_pairs``, over their largest
  possible value, 8/3 (half-turns about axes spread over the sphere);
- *image*: the share of an image grid's cells holding a feature, averaged over both cameras;
- *joints*: the share of (joint, bin) cells the views' joint values occupy, ``bins`` equal bins
  per joint over the range the hole tour uses (``joint_box``; a value outside earns nothing).

**Information-based design** (:func:`choose_by_information`): given each candidate's Fisher
information block ``J_v^T J_v / σ²`` of the calibration parameters (from the adjustment's own
Jacobian) and a prior information, greedy selection then single exchanges (Fedorov) minimise
``trace(W M^-1)`` (``W`` given: an I-optimal design, e.g. the TCP error at the hole tour's stops)
or maximise ``log det M`` (``W`` is ``None``: D-optimal).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from planner.calibration.candidates import Candidates
from planner.errors import PlanningError
from robots import design
from robots.errors import DesignError

#: the largest mean eigenvalue of (R - I)^T (R - I) over pairs (half-turns, axes spread evenly)
ROTATION_SCALE = 8.0 / 3.0
#: a step's separation share is full from this rotation to the nearest chosen view on (60 deg)
SEPARATION_RAD = np.pi / 3


@dataclass(frozen=True)
class GeometryScore:
    """A set of views' geometric figures (module docstring): shares in [0, 1], angles in rad.

    ``rotation`` / ``image`` / ``joints``: the three shares; ``min_rotation_rad``: the smallest
    rotation between two stations; ``axis_eigen_min``: the smallest eigenvalue of ``M / n_pairs``
    (0: every rotation about parallel axes).
    """

    rotation: float
    image: float
    joints: float
    min_rotation_rad: float
    axis_eigen_min: float

    @property
    def total(self) -> float:
        """The greedy's score: the sum of the three shares."""
        return self.rotation + self.image + self.joints


def _rotation_share(M: NDArray[np.float64], pairs: int) -> NDArray[np.float64]:
    """Rotation share of stacked ``M`` (..., 3, 3) summed over ``pairs`` pairs."""
    if pairs == 0:
        return np.zeros(M.shape[:-2])
    ev = np.clip(np.linalg.eigvalsh(M / pairs), 0.0, None)
    geo = np.cbrt(np.prod(ev, axis=-1))
    return 0.5 * (geo + ev.mean(axis=-1)) / ROTATION_SCALE


def grid_cells(
    uv: NDArray[np.float64], image_size: tuple[int, int], grid: tuple[int, int]
) -> NDArray[np.bool_]:
    """(m, gx*gy): which cells of a ``grid`` over the image each view's pixels (m, n, 2) hit."""
    w, h = image_size
    gx = np.clip((uv[..., 0] / w * grid[0]).astype(int), 0, grid[0] - 1)
    gy = np.clip((uv[..., 1] / h * grid[1]).astype(int), 0, grid[1] - 1)
    cells = np.zeros((uv.shape[0], grid[0] * grid[1]), dtype=bool)
    rows = np.repeat(np.arange(uv.shape[0]), uv.shape[1])
    cells[rows, (gy * grid[0] + gx).ravel()] = True
    return cells


def joint_bins(
    q: NDArray[np.float64], joint_box: tuple[NDArray[np.float64], NDArray[np.float64]], bins: int
) -> NDArray[np.bool_]:
    """(m, dof*bins): which (joint, bin) cells of ``joint_box`` (lower, upper, rad) each view's
    ``q`` (m, dof) occupies (none for a joint value outside the box)."""
    lo, hi = (np.asarray(v, dtype=float) for v in joint_box)
    span = np.maximum(hi - lo, 1e-9)
    u = (q - lo) / span
    inside = (u >= 0) & (u <= 1)
    b = np.clip((u * bins).astype(int), 0, bins - 1)
    dof = q.shape[1]
    cells = np.zeros((len(q), dof * bins), dtype=bool)
    r, j = np.nonzero(inside)
    cells[r, j * bins + b[r, j]] = True
    return cells


@dataclass(frozen=True)
class PreselectOptions:
    """The geometric pre-selection's image ``grid`` (columns, rows) and ``bins`` per joint."""

    grid: tuple[int, int] = (6, 5)
    bins: int = 4


def geometry_score(
    c: Candidates,
    rows: list[int],
    image_size: tuple[int, int],
    joint_box: tuple[NDArray[np.float64], NDArray[np.float64]],
    options: PreselectOptions | None = None,
) -> GeometryScore:
    """The geometric figures of the views ``rows`` of ``c`` (module docstring)."""
    o = options or PreselectOptions()
    R = c.T_cell_tcp[rows, :3, :3]
    n = len(rows)
    M = np.zeros((3, 3))
    min_angle = np.pi
    for i in range(n):
        for j in range(i + 1, n):
            Rij = R[i].T @ R[j]
            M += 2.0 * np.eye(3) - Rij - Rij.T
            min_angle = min(min_angle, float(np.arccos(np.clip((np.trace(Rij) - 1) / 2, -1, 1))))
    pairs = n * (n - 1) // 2
    left = grid_cells(c.uv_left[rows], image_size, o.grid).any(axis=0)
    right = grid_cells(c.uv_right[rows], image_size, o.grid).any(axis=0)
    joints = joint_bins(c.q[rows], joint_box, o.bins).any(axis=0)
    ev_min = float(np.linalg.eigvalsh(M / pairs)[0]) if pairs else 0.0
    return GeometryScore(
        rotation=float(_rotation_share(M, pairs)),
        image=float(0.5 * (left.mean() + right.mean())),
        joints=float(joints.mean()),
        min_rotation_rad=min_angle if pairs else 0.0,
        axis_eigen_min=max(ev_min, 0.0),
    )


def preselect(
    c: Candidates,
    n: int,
    image_size: tuple[int, int],
    joint_box: tuple[NDArray[np.float64], NDArray[np.float64]],
    options: PreselectOptions | None = None,
) -> list[int]:
    """Greedily ``n`` rows of ``c`` maximising the geometric score (module docstring).

    Starts from the view whose features cover most of both images; ties go to the lower row,
    so the choice is deterministic."""
    if n < 1:
        raise PlanningError(f"the number of calibration views must be at least 1, got {n}")
    o = options or PreselectOptions()
    m = len(c)
    n = min(n, m)
    R = c.T_cell_tcp[:, :3, :3]
    cl = grid_cells(c.uv_left, image_size, o.grid)
    cr = grid_cells(c.uv_right, image_size, o.grid)
    jb = joint_bins(c.q, joint_box, o.bins)
    chosen = [int(np.argmax(c.coverage.sum(axis=1)))]
    A = R[chosen[0]].copy()  # sum of the chosen rotations
    M = np.zeros((3, 3))
    occ_l, occ_r, occ_j = cl[chosen[0]].copy(), cr[chosen[0]].copy(), jb[chosen[0]].copy()
    free = np.ones(m, dtype=bool)
    free[chosen[0]] = False
    nearest = _angles(R, R[chosen[0]])  # each candidate's rotation to the nearest chosen view
    while len(chosen) < n:
        k = len(chosen)
        # M + sum_i (2I - R_i^T R_j - R_j^T R_i) for every candidate j at once
        AtR = np.einsum("ba,jbc->jac", A, R)
        Mj = M + 2.0 * k * np.eye(3) - AtR - np.transpose(AtR, (0, 2, 1))
        pairs = k * (k + 1) // 2
        score = _rotation_share(Mj, pairs)
        score = score + 0.5 * ((occ_l | cl).mean(axis=1) + (occ_r | cr).mean(axis=1))
        score = score + (occ_j | jb).mean(axis=1)
        score = score + np.minimum(nearest / SEPARATION_RAD, 1.0)
        score[~free] = -np.inf
        j = int(np.argmax(score))
        chosen.append(j)
        free[j] = False
        M = Mj[j]
        A += R[j]
        occ_l |= cl[j]
        occ_r |= cr[j]
        occ_j |= jb[j]
        nearest = np.minimum(nearest, _angles(R, R[j]))
    return chosen


def _angles(R: NDArray[np.float64], R0: NDArray[np.float64]) -> NDArray[np.float64]:
    """Rotation angle (rad) from ``R0`` (3, 3) to each of ``R`` (m, 3, 3)."""
    tr = np.einsum("ab,mab->m", R0, R)
    return np.arccos(np.clip((tr - 1.0) / 2.0, -1.0, 1.0))


def choose_by_information(
    blocks: NDArray[np.float64],
    n: int,
    prior: NDArray[np.float64],
    W: NDArray[np.float64] | None = None,
    exchange_passes: int = 10,
    start: list[int] | None = None,
    factors: NDArray[np.float64] | None = None,
) -> list[int]:
    """:func:`robots.design.choose_by_information` for calibration views (module docstring);
    a design that cannot be chosen is a :class:`planner.errors.PlanningError`."""
    try:
        return design.choose_by_information(blocks, n, prior, W, exchange_passes, start, factors)
    except DesignError as exc:
        raise PlanningError(f"calibration views: {exc}") from exc
