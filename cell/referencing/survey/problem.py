"""The survey's adjustment problem, kept apart from the solvers: the markers' ideal-pixel
observations in both cameras of every view, the head as one rigid stereo body with its
calibration (camera matrices and ``T_left_right``) taken as known, the scale bars, and the
starting values (the nominal markers, the arm's view poses).

Unknowns: every view's left-camera pose ``T_cell_left`` and every marker's centre (cell frame).
The datum is free: the solvers hold view 0 by a tight prior and :mod:`.gauge` moves the result
to the fixture markers' nominal positions afterwards. The scale comes from the head's baseline
(about 100 ppm alone) and the scale bars.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np
from numpy.typing import NDArray

from cell.referencing.observations import MarkerView, T_left_right, ideal_pixels
from cell.uncertainty.calibration import default_uncertainty
from measure import StereoCalibration

Array = NDArray[np.float64]


@dataclass(frozen=True)
class ScaleBarObs:
    """A scale bar between markers ``i`` and ``j`` (rows of the problem): length and its
    standard uncertainty (m)."""

    i: int
    j: int
    length_m: float
    sigma_m: float


@dataclass(frozen=True)
class SurveyProblem:
    """Observation ``k``: view ``view[k]`` saw marker ``marker[k]`` in camera ``side[k]`` (0 left,
    1 right) at ideal pixel ``uv[k]``; ``sigma_px`` its standard deviation."""

    marker_ids: tuple[str, ...]
    view_ids: tuple[str, ...]
    view: NDArray[np.int64]
    marker: NDArray[np.int64]
    side: NDArray[np.int64]
    uv: Array
    sigma_px: float
    K: tuple[Array, Array]
    T_left_right: Array
    bars: tuple[ScaleBarObs, ...]
    points0: Array
    poses0: Array  # (V, 4, 4) T_cell_left
    #: the head's stated standard deviations, the priors of its self-calibration: per camera
    #: (fx, fy, cx, cy) px, and the rig's rotation (3, rad) and translation (3, m)
    K_sigma: tuple[Array, Array] = (np.full(4, 0.3), np.full(4, 0.3))
    rig_sigma: Array = field(default_factory=lambda: np.array([1e-5, 5e-5, 2e-5, 5e-6, 2e-6, 1e-5]))
    #: per camera, the stated sigma of the lens terms the survey refines (k1, k2, p1, p2)
    dist_sigma: tuple[Array, Array] = (np.array([2e-4, 2e-3, 2e-5, 2e-5]),) * 2

    @property
    def n_views(self) -> int:
        return len(self.view_ids)

    @property
    def n_markers(self) -> int:
        return len(self.marker_ids)

    def without(self, keep: NDArray[np.bool_]) -> SurveyProblem:
        """The same problem with only the observations ``keep``."""
        return replace(
            self,
            view=self.view[keep],
            marker=self.marker[keep],
            side=self.side[keep],
            uv=self.uv[keep],
        )


def build_problem(
    views: list[MarkerView],
    stereo: StereoCalibration,
    marker_ids: list[str],
    nominal_cell: Array,
    bars: list[tuple[str, str, float, float]],
    sigma_px: float,
) -> SurveyProblem:
    """The problem of ``views`` of the markers ``marker_ids`` (nominal centres (n, 3), cell
    frame: the starting values); ``bars``: ``(from id, to id, length_m, U_m at k = 2)``."""
    index = {m: k for k, m in enumerate(marker_ids)}
    rows_v, rows_m, rows_s, rows_uv = [], [], [], []
    for v, view in enumerate(views):
        for s, (side, seen) in enumerate((("left", view.uv_left), ("right", view.uv_right))):
            ids = [m for m in sorted(seen) if m in index]
            if not ids:
                continue
            uv = ideal_pixels(stereo, side, np.array([seen[m] for m in ids]))
            rows_v += [v] * len(ids)
            rows_m += [index[m] for m in ids]
            rows_s += [s] * len(ids)
            rows_uv.append(uv)
    bar_obs = tuple(
        ScaleBarObs(index[a], index[b], float(length), float(U) / 2.0)
        for a, b, length, U in bars
        if a in index and b in index
    )
    unc = stereo.uncertainty or default_uncertainty(stereo)
    return SurveyProblem(
        K_sigma=(np.asarray(unc.K_std_left_px, float), np.asarray(unc.K_std_right_px, float)),
        rig_sigma=np.concatenate([unc.rvec_std_rad, unc.T_std_m]).astype(float),
        dist_sigma=(
            np.asarray(unc.dist_std_left, float)[:4],
            np.asarray(unc.dist_std_right, float)[:4],
        ),
        marker_ids=tuple(marker_ids),
        view_ids=tuple(v.view_id for v in views),
        view=np.array(rows_v, dtype=np.int64),
        marker=np.array(rows_m, dtype=np.int64),
        side=np.array(rows_s, dtype=np.int64),
        uv=np.vstack(rows_uv) if rows_uv else np.zeros((0, 2)),
        sigma_px=float(sigma_px),
        K=(np.asarray(stereo.K_left, float), np.asarray(stereo.K_right, float)),
        T_left_right=T_left_right(stereo),
        bars=bar_obs,
        points0=np.asarray(nominal_cell, float).reshape(-1, 3),
        poses0=np.array([v.T_cell_left_prior for v in views], dtype=float).reshape(-1, 4, 4),
    )


#: a self-calibrated head: (K_left, K_right, T_left_right, residual lens terms left, right),
#: the lens terms ``(k1, k2, p1, p2)`` applied to the ideal pixels' normalised coordinates
Head = tuple[Array, Array, Array, Array, Array]


def residual_distortion(x: Array, d: Array) -> Array:
    """Normalised coordinates (k, 2) moved by the lens terms ``d = (k1, k2, p1, p2)`` (OpenCV's
    and GTSAM's Cal3DS2 model)."""
    k1, k2, p1, p2 = d
    u, v = x[:, 0], x[:, 1]
    r2 = u * u + v * v
    g = 1.0 + k1 * r2 + k2 * r2 * r2
    return np.stack(
        [
            u * g + 2 * p1 * u * v + p2 * (r2 + 2 * u * u),
            v * g + p1 * (r2 + 2 * v * v) + 2 * p2 * u * v,
        ],
        axis=1,
    )


def predict(problem: SurveyProblem, poses: Array, points: Array, head: Head | None = None) -> Array:
    """Ideal pixels (k, 2) of every observation for view poses (V, 4, 4) and points (n, 3);
    ``head``: the self-calibrated head (:data:`Head`; None: the problem's, no lens terms)."""
    if head is None:
        head = (problem.K[0], problem.K[1], problem.T_left_right, np.zeros(4), np.zeros(4))
    K_l, K_r, T_lr, d_l, d_r = head
    T = poses[problem.view].copy()
    right = problem.side == 1
    T[right] = T[right] @ T_lr
    R, t = T[:, :3, :3], T[:, :3, 3]
    p_cam = np.einsum("kji,kj->ki", R, points[problem.marker] - t)  # R^T (p - t)
    x = p_cam[:, :2] / p_cam[:, 2:3]
    x = np.where(right[:, None], residual_distortion(x, d_r), residual_distortion(x, d_l))
    K = np.where(right[:, None, None], K_r, K_l)
    return np.einsum("kij,kj->ki", K[:, :2, :2], x) + K[:, :2, 2]
