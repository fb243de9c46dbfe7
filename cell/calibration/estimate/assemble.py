"""The result of the adjustment put together:
:class:`~cell.calibration.estimate.result.CellCalibration`."""

from __future__ import annotations

from datetime import UTC, datetime

import numpy as np
from numpy.typing import NDArray

from cell.calibration.estimate.covariance import CovarianceResult
from cell.calibration.estimate.identifiability import IdentifiabilityReport
from cell.calibration.estimate.initial import InitialEstimate
from cell.calibration.estimate.model import POSE_COLUMNS, Prediction, State
from cell.calibration.estimate.observations import CalibrationObservations
from cell.calibration.estimate.result import (
    CellCalibration,
    DHTermEstimate,
    PoseEstimate,
    Provenance,
    ViewResidual,
)
from robots.calibration import term_names
from robots.dh import DHTable

Array = NDArray[np.float64]


def _pose_block(cov: Array, free: tuple[str, ...], prefix: str) -> Array:
    names = [f"{prefix}.{c}" for c in POSE_COLUMNS]
    out = np.zeros((6, 6))
    for i, a in enumerate(names):
        for j, b in enumerate(names):
            if a in free and b in free:
                out[i, j] = cov[free.index(a), free.index(b)]
    return out


def build_calibration(
    obs: CalibrationObservations,
    dh: DHTable | None,
    state: State,
    report: IdentifiabilityReport,
    cr: CovarianceResult,
    pred: Prediction,
    prov: Provenance,
    init: InitialEstimate | None,
) -> CellCalibration:
    """The :class:`CellCalibration` of a solved adjustment: estimates, covariance blocks,
    D-H terms (free and fixed with reasons), residuals per view and camera, counts, notes."""
    free = report.free
    cov, s2 = cr.covariance, cr.s2_px
    terms: tuple[DHTermEstimate, ...] = ()
    if dh is not None and obs.has_joints:
        terms = tuple(
            DHTermEstimate(
                name=n,
                value=float(state.delta[k]),
                sigma=float(np.sqrt(cov[free.index(f"dh.{n}")][free.index(f"dh.{n}")]))
                if f"dh.{n}" in free
                else 0.0,
                free=f"dh.{n}" in free,
                reason=report.fixed.get(f"dh.{n}", ""),
            )
            for k, n in enumerate(term_names())
        )
    M = len(obs.target.object_points())
    r2 = pred.residuals.reshape(-1, 2)
    views = []
    for i, v in enumerate(obs.views):
        rms = {}
        for side in ("left", "right"):
            sel = (pred.view_index == i) & (pred.camera == side)
            rms[side] = (
                float(np.sqrt(np.mean(np.sum(r2[sel] ** 2, axis=1)))) if sel.any() else float("nan")
            )
        views.append(
            ViewResidual(v.name, rms["left"], rms["right"], int((pred.view_index == i).sum()))
        )
    per_cam = {}
    for side in ("left", "right"):
        sel = pred.camera == side
        if sel.any():
            per_cam[side] = float(np.sqrt(np.mean(np.sum(r2[sel] ** 2, axis=1))))
    notes = []
    if init is not None:
        notes.append(
            f"start: OpenCV hand-eye method {init.best.method} "
            f"(the most consistent of {len(init.candidates)})"
        )
    if cr.source == "not modelled" or cr.source.startswith("not modelled"):
        notes.append(
            "covariance: s^2 (J^T J)^-1, s^2 from the residuals (corner noise only; flange "
            f"scatter {cr.source}); intrinsics and target geometry taken as exact"
        )
    else:
        notes.append(
            f"covariance: corner noise s = {np.sqrt(s2):.3f} px and each view's flange pose "
            f"scatter {cr.flange_sigma_m * 1e3:.3f} mm, {np.rad2deg(cr.flange_sigma_rad):.4f} deg "
            f"per axis ({cr.source}); {cr.method}; intrinsics "
            "and target geometry taken as exact"
        )
    med = np.nanmedian([v.rms_left_px for v in views])
    for v in views:
        if v.rms_left_px > 3 * med and v.rms_left_px > 0.5:
            notes.append(
                f"warning: view {v.name} fits {v.rms_left_px:.2f} px, "
                f"more than 3x the median {med:.2f} px"
            )
    n, p = len(pred.residuals), len(free)
    return CellCalibration(
        T_tool0_camera=PoseEstimate(state.T_tool0_camera, _pose_block(cov, free, "T_tool0_camera")),
        T_base_target=PoseEstimate(state.T_base_target, _pose_block(cov, free, "T_base_target")),
        T_left_right=None
        if state.T_left_right is None
        else PoseEstimate(state.T_left_right, _pose_block(cov, free, "T_left_right")),
        nominal_dh=dh if terms else None,
        dh_terms=terms,
        parameter_names=free,
        covariance=cov,
        sigma_px=float(np.sqrt(s2)),
        residual_rms_px=per_cam,
        views=tuple(views),
        counts={
            "views": len(obs.views),
            "points": n // 2,
            "residuals": n,
            "parameters": p,
            "dof": n - p,
            "corners_per_view": M,
        },
        target={
            "kind": obs.target.kind,
            "cols": obs.target.cols,
            "rows": obs.target.rows,
            "pitch_m": obs.target.pitch_m,
        },
        provenance=prov,
        created_utc=datetime.now(UTC).strftime("%Y-%m-%dT%H:%M:%SZ"),
        notes=tuple(notes),
        flange_scatter={
            "sigma_m": cr.flange_sigma_m,
            "sigma_rad": cr.flange_sigma_rad,
            "source": cr.source,
        },
    )
