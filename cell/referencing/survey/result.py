"""A survey's result: every marker's centre and covariance in the gauge, with the figures a
metrology engineer checks (residuals, variance factor, scale and its source, the gauge)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from measure import StereoCalibration

Array = NDArray[np.float64]


@dataclass(frozen=True)
class SurveyResult:
    """``positions_cell`` (n, 3) m and ``covariance`` (3n, 3n) m² of ``marker_ids`` in the cell
    frame, in the gauge ``gauge`` (``"fixture markers"`` or ``"all markers"``: a rigid fit to
    their nominal positions, ``gauge_residuals_m`` their distances after it).

    ``rms_px``: the image residual RMS (ideal pixels), ``variance_factor`` chi2 / dof at the
    stated centre noise ``sigma_px``; ``sigma_effective_px``: the centre noise the final
    adjustment weighed with and its covariance is stated at (the a posteriori noise, not below
    ``sigma_floor_px``: :mod:`cell.referencing.sigma`); ``scale_sigma_ppm``: the network's scale
    uncertainty (from the scale bars and the head's baseline), ``scale_source`` says which;
    ``dropped_views``: views left out (too few markers, or on one line); ``outliers``: the
    observations dropped above the outlier limit, as ``(view, marker, camera, normalised
    residual)``; ``warnings``: one line each; ``timings``: s; ``stereo``: the head as the survey
    self-calibrated it (camera matrices and rig; ``stereo.json``'s lens model), the head every
    referenced stop then measures with."""

    marker_ids: tuple[str, ...]
    positions_cell: Array
    covariance: Array
    gauge: str
    gauge_residuals_m: Array
    rms_px: float
    variance_factor: float
    n_views: int
    n_observations: int
    scale_sigma_ppm: float
    scale_source: str
    dropped_views: tuple[str, ...] = ()
    outliers: tuple[tuple[str, str, str, float], ...] = ()
    warnings: tuple[str, ...] = ()
    timings: dict[str, float] = field(default_factory=dict)
    sigma_px: float = 0.05
    stereo: StereoCalibration | None = None
    sigma_effective_px: float = 0.05
    sigma_floor_px: float = 0.02

    def sigma_m(self) -> Array:
        """Per-marker standard deviations (n, 3) m along the cell axes."""
        return np.sqrt(np.diag(self.covariance)).reshape(-1, 3)

    def position(self, marker_id: str) -> Array:
        return self.positions_cell[self.marker_ids.index(marker_id)]
