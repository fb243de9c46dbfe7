"""Locating one stop against the surveyed markers: the head's pose ``T_cell_left`` from the
markers both of its cameras see (stereo resection), robust, with its covariance.

Unknowns: ``T_cell_left = (R0 exp(w), t0 + tau)`` about the arm's prior ``(R0, t0)``. The
markers' ideal-pixel residuals in both cameras are minimised (Levenberg-Marquardt, SciPy; six
unknowns). A marker whose residual exceeds :data:`OUTLIER_SIGMA` (it moved since the survey, or
it is misidentified) is refused by id and the pose solved again while at least
:data:`MIN_MARKERS` remain; with fewer the stop is not referenced (``ok`` False: the run falls
back to the arm). The covariance holds the image noise and the survey's marker covariance
(``A C_markers A^T`` with ``A = (J^T J)^-1 J^T J_markers``). :func:`resect_near` takes one
Gauss-Newton step instead, from a pose already resected from nearly the same centres.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import least_squares

from cell.referencing.observations import MarkerView, T_left_right, ideal_pixels
from measure import StereoCalibration
from robots.transforms import skew, so3_exp, so3_left_jacobian

Array = NDArray[np.float64]

#: a stop is referenced with at least this many markers
MIN_MARKERS = 4
#: a marker this many sigma off the others is refused
OUTLIER_SIGMA = 5.0
#: Levenberg-Marquardt's stops: the relative change of the cost, and of the step against the
#: increment about the prior (about 1e-3 from the arm: 1e-13 m and rad, far below any figure).
#: The unknowns are unscaled (``x_scale=1``: rad and m, alike at the head's 0.25 m standoff): the
#: first step is then Gauss-Newton's, where MINPACK's Jacobian scaling (the pixels weighed at
#: 0.05 px) bounded it to a third of a 2 mm prior error and took 8 iterations, not 4
FTOL, XTOL = 1e-10, 1e-10


@dataclass(frozen=True)
class Resection:
    """The located stop: ``T_cell_left`` (4, 4) and the covariance (6, 6) of ``(w, tau)`` (rad,
    m; ``w`` turns the left camera's own axes, ``tau`` moves its origin); ``used`` and
    ``refused`` (id -> reason) markers; ``rms_px`` the residual RMS; ``ok`` False when fewer
    than :data:`MIN_MARKERS` markers remain (``reason`` says why). ``covariance_markers``: the
    part of ``covariance`` that comes from the survey's marker covariance (the rest is the
    image noise's)."""

    ok: bool
    T_cell_left: Array
    covariance: Array
    used: tuple[str, ...]
    refused: dict[str, str] = field(default_factory=dict)
    rms_px: float = float("nan")
    reason: str = ""
    covariance_markers: Array | None = None
    #: d (w, tau) / d (the used markers' positions) (6, 3k), and the markers' indices in the
    #: network (k,): how the survey's marker errors move this stop (shared by the stops that
    #: use the same markers)
    marker_sensitivity: Array | None = None
    marker_columns: tuple[int, ...] = ()

    def point_jacobian(self, p_left: Array) -> Array:
        """d p_cell / d (w, tau) (3, 6) of a point ``p_left`` (m) of the left camera frame."""
        R = self.T_cell_left[:3, :3]
        return np.hstack([-R @ skew(np.asarray(p_left, float)), np.eye(3)])

    def point(self, p_left: Array, cov_left: Array | None = None) -> tuple[Array, Array]:
        """A point measured in the left camera frame, in the cell frame, and its covariance
        (3, 3) m²: the resection's and (when given) the point's own."""
        R, t = self.T_cell_left[:3, :3], self.T_cell_left[:3, 3]
        p_left = np.asarray(p_left, float)
        J = self.point_jacobian(p_left)
        cov = J @ self.covariance @ J.T
        if cov_left is not None:
            cov = cov + R @ np.asarray(cov_left, float) @ R.T
        return R @ p_left + t, cov


def _pose(T0: Array, x: Array) -> Array:
    T = T0.copy()
    T[:3, :3] = T0[:3, :3] @ so3_exp(x[:3])
    T[:3, 3] = T0[:3, 3] + x[3:]
    return T


class _Obs:
    """Ideal-pixel observations of one view: rows (marker index, camera, uv)."""

    def __init__(self, view: MarkerView, stereo: StereoCalibration, index: dict[str, int]):
        rows, uvs = [], []
        for side, seen in enumerate((view.uv_left, view.uv_right)):
            ids = [m for m in sorted(seen) if m in index]
            if ids:
                name = ("left", "right")[side]
                uvs.append(ideal_pixels(stereo, name, np.array([seen[m] for m in ids])))
                rows += [(index[m], side) for m in ids]
        self.marker = np.array([r[0] for r in rows], dtype=np.int64)
        self.side = np.array([r[1] for r in rows], dtype=np.int64)
        self.uv = np.vstack(uvs) if uvs else np.zeros((0, 2))

    def keep(self, mask: NDArray[np.bool_]) -> None:
        self.marker, self.side, self.uv = self.marker[mask], self.side[mask], self.uv[mask]


def _camera_points(
    x: Array, T0: Array, obs: _Obs, P: Array, T_lr: Array
) -> tuple[Array, Array, Array]:
    """The left camera's rotation ``R`` (3, 3) at ``x``, each row's marker in the left camera's
    frame ``q = R^T (P - t)`` and in its own camera's ``pc`` (the right's: ``R_lr^T (q -
    t_lr)``), (k, 3) m."""
    T = _pose(T0, x)
    R = T[:3, :3]
    q = (P[obs.marker] - T[:3, 3]) @ R
    pc = q.copy()
    right = obs.side == 1
    pc[right] = (q[right] - T_lr[:3, 3]) @ T_lr[:3, :3]
    return R, q, pc


def _residuals(
    x: Array, T0: Array, obs: _Obs, P: Array, K: tuple[Array, Array], T_lr: Array, sigma: float
) -> Array:
    """Projected minus observed ideal pixels over ``sigma``, both cameras' rows at once."""
    _, _, pc = _camera_points(x, T0, obs, P, T_lr)
    Kr = np.stack(K)[obs.side]
    uv = (Kr[:, :2, :2] @ (pc[:, :2] / pc[:, 2:3])[:, :, None])[:, :, 0] + Kr[:, :2, 2]
    return ((uv - obs.uv) / sigma).ravel()


def _pose_jacobian(
    x: Array, T0: Array, obs: _Obs, P: Array, K: tuple[Array, Array], T_lr: Array, sigma: float
) -> Array:
    """d :func:`_residuals` / d x (k, 6), analytic. With ``R = R0 exp(w)``, a change ``d`` of
    ``w`` turns ``R`` by ``phi = J_r(w) d`` on the right; the left camera's point
    ``q = R^T (P - t)`` moves by ``[q]x phi``, the right camera's ``R_lr^T (q - t_lr)`` by
    ``R_lr^T [q]x phi``; a change of ``t`` moves either by ``-R_cam^T`` (``R_lr^T R^T`` for the
    right); then ``d uv / d p = K2 [[1/z, 0, -x/z^2], [0, 1/z, -y/z^2]]`` (``K2`` the focal part
    of the row's camera matrix) over the pixel sigma. Every row at once."""
    R, q, pc = _camera_points(x, T0, obs, P, T_lr)
    z = pc[:, 2]
    D = np.zeros((len(z), 2, 3))
    D[:, 0, 0] = D[:, 1, 1] = 1.0 / z
    D[:, 0, 2], D[:, 1, 2] = -pc[:, 0] / z**2, -pc[:, 1] / z**2
    A = np.stack([np.eye(3), T_lr[:3, :3].T])[obs.side]  # the row's camera from the left's
    M = (np.stack(K)[obs.side][:, :2, :2] / sigma) @ D @ A  # (k, 2, 3)
    skews = np.zeros((len(z), 3, 3))
    skews[:, 0, 1], skews[:, 0, 2], skews[:, 1, 2] = -q[:, 2], q[:, 1], -q[:, 0]
    skews[:, 1, 0], skews[:, 2, 0], skews[:, 2, 1] = q[:, 2], -q[:, 1], q[:, 0]
    Jw = M @ skews @ so3_left_jacobian(-np.asarray(x[:3], float))
    return np.concatenate([Jw, -M @ R.T], axis=2).reshape(-1, 6)


def _problem(
    view: MarkerView,
    stereo: StereoCalibration,
    marker_ids: tuple[str, ...],
    positions: Array,
    sigma_px: float,
) -> tuple[dict[str, int], tuple]:
    """The markers' index by id and the arguments of :func:`_residuals` and
    :func:`_pose_jacobian` for ``view``: ``(T0, obs, positions, K, T_lr, sigma_px)``."""
    index = {m: k for k, m in enumerate(marker_ids)}
    K = (np.asarray(stereo.K_left, float), np.asarray(stereo.K_right, float))
    T0 = np.asarray(view.T_cell_left_prior, float)
    return index, (T0, _Obs(view, stereo, index), positions, K, T_left_right(stereo), sigma_px)


def resect(
    view: MarkerView,
    stereo: StereoCalibration,
    marker_ids: tuple[str, ...],
    positions: Array,
    covariance: Array | None,
    sigma_px: float,
    image_sigma_px: float | None = None,
) -> Resection:
    """Locate ``view`` against the surveyed markers ``marker_ids`` (positions (n, 3) m, cell
    frame; their covariance (3n, 3n) m² or None) (module doc). ``sigma_px`` weighs the centres
    and sets the outlier limit; the image noise's covariance is stated at ``image_sigma_px``
    (default ``sigma_px``; :mod:`cell.referencing.sigma`)."""
    index, args = _problem(view, stereo, marker_ids, positions, sigma_px)
    obs = args[1]
    refused: dict[str, str] = {}
    while True:
        used = sorted({marker_ids[j] for j in obs.marker})
        if len(used) < MIN_MARKERS:
            why = f"{len(used)} usable markers, {MIN_MARKERS} needed"
            return Resection(False, args[0], np.full((6, 6), np.nan), tuple(used), refused,
                             reason=why)  # fmt: skip
        sol = least_squares(_residuals, np.zeros(6), jac=_pose_jacobian, args=args, method="lm",
                            x_scale=1.0, xtol=XTOL, ftol=FTOL)  # fmt: skip
        r = sol.fun.reshape(-1, 2)
        per = np.linalg.norm(r, axis=1) / np.sqrt(2.0)
        worst = int(np.argmax(per))
        if per[worst] <= OUTLIER_SIGMA:
            break
        bad = marker_ids[obs.marker[worst]]
        refused[bad] = f"{per[worst]:.1f} sigma off the other markers (moved since the survey?)"
        obs.keep(obs.marker != index[bad])
    return _located(sol.x, sol.jac, r, args, tuple(used), refused, covariance, image_sigma_px)


def resect_near(
    view: MarkerView,
    stereo: StereoCalibration,
    marker_ids: tuple[str, ...],
    positions: Array,
    covariance: Array | None,
    sigma_px: float,
    image_sigma_px: float | None = None,
) -> Resection:
    """:func:`resect` of a view whose prior is already the pose a resection found from nearly
    the same centres (the second pass of :func:`cell.run.referenced.locate_stop`: the markers'
    perspective bias removed at that pose, a change of about 0.001 px): one Gauss-Newton step.
    The step's error is what Gauss-Newton leaves with non-zero residuals, a fraction of the
    change itself: with centres moved by 0.002 px, under a nanometre at the hole (test); on the
    demo's stops the poses agree with the full resection's to 2e-10. When a marker then lies
    over :data:`OUTLIER_SIGMA`, or fewer than :data:`MIN_MARKERS` remain, the full
    :func:`resect` decides."""
    _, args = _problem(view, stereo, marker_ids, positions, sigma_px)
    used = sorted({marker_ids[j] for j in args[1].marker})
    if len(used) >= MIN_MARKERS:
        J0, r0 = _pose_jacobian(np.zeros(6), *args), _residuals(np.zeros(6), *args)
        x = -np.linalg.solve(J0.T @ J0, J0.T @ r0)
        r = _residuals(x, *args).reshape(-1, 2)
        if np.linalg.norm(r, axis=1).max() / np.sqrt(2.0) <= OUTLIER_SIGMA:
            J = _pose_jacobian(x, *args)
            return _located(x, J, r, args, tuple(used), {}, covariance, image_sigma_px)
    return resect(view, stereo, marker_ids, positions, covariance, sigma_px, image_sigma_px)


def _located(
    x: Array,
    J: Array,
    r: Array,
    args: tuple,
    used: tuple[str, ...],
    refused: dict[str, str],
    covariance: Array | None,
    image_sigma_px: float | None,
) -> Resection:
    """The :class:`Resection` at the solution ``x`` (pose Jacobian ``J``, residuals ``r``
    (k, 2) in sigmas): its covariance from the image noise and, given the markers'
    ``covariance``, the survey's."""
    T0, obs, _, _, _, sigma_px = args
    JtJ_inv = np.linalg.inv(J.T @ J)
    cov = JtJ_inv * ((image_sigma_px or sigma_px) / sigma_px) ** 2
    cov_markers = np.zeros((6, 6))
    Jm, cols = _marker_jacobian(J, obs)
    A = None
    if covariance is not None:
        idx = (3 * cols[:, None] + np.arange(3)).ravel()
        A = JtJ_inv @ J.T @ Jm
        cov_markers = A @ covariance[np.ix_(idx, idx)] @ A.T
        cov = cov + cov_markers
    rms = float(np.sqrt(np.mean((r * sigma_px) ** 2)))
    return Resection(True, _pose(T0, x), cov, used, refused, rms, "", cov_markers, A,
                     tuple(int(c) for c in cols))  # fmt: skip


def _marker_jacobian(J: Array, obs: _Obs) -> tuple[Array, Array]:
    """d residuals / d the positions of the markers the rows see (2k, 3m), and those markers'
    indices (m,): moving a marker by ``d`` is moving the camera by ``-d``, so each row's block
    is minus the pose Jacobian's translation columns ``J[:, 3:]`` (k rows of :func:`_residuals`
    at the same pose)."""
    cols, where = np.unique(obs.marker, return_inverse=True)
    Jm = np.zeros((len(J), 3 * len(cols)))
    Jm[np.arange(len(J))[:, None], 3 * np.repeat(where, 2)[:, None] + np.arange(3)] = -J[:, 3:]
    return Jm, cols


def pose_sensitivity(
    view: MarkerView,
    marker_ids: tuple[str, ...],
    positions: Array,
    T_cell_left: Array,
    heads: list[StereoCalibration],
) -> list[Array]:
    """The pose a resection of ``view`` (the markers ``marker_ids`` at ``positions``, every one
    used) gives with each head of ``heads`` (the first: the head ``T_cell_left`` was resected
    with), to first order: one Gauss-Newton step from ``T_cell_left`` with the first head's
    Jacobian (forward differences of the pose's six increments). For a head's small changes
    (a calibration's sigma) this is the full resection's change to second order, at the cost of
    one evaluation of the residuals per head instead of a solve."""
    index = {m: k for k, m in enumerate(marker_ids)}
    T0 = np.asarray(T_cell_left, float)

    def residuals(head: StereoCalibration, x: Array) -> Array:
        obs = _Obs(view, head, index)
        K = (np.asarray(head.K_left, float), np.asarray(head.K_right, float))
        return _residuals(x, T0, obs, positions, K, T_left_right(head), 1.0)

    r0 = residuals(heads[0], np.zeros(6))
    h = 1e-7
    J = np.column_stack([(residuals(heads[0], h * e) - r0) / h for e in np.eye(6)])
    step = np.linalg.pinv(J)
    return [_pose(T0, -step @ residuals(head, np.zeros(6))) for head in heads]
