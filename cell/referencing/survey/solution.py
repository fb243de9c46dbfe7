"""What a survey solver returns, before the gauge."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

Array = NDArray[np.float64]


@dataclass(frozen=True)
class RawSolution:
    """Marker centres (n, 3) m and view poses (V, 4, 4) in the solver's datum (view 0 held);
    ``covariance``: the markers' joint covariance (3n, 3n) m² (None: not computed); ``chi2`` the
    weighted squared residual sum with ``dof`` degrees of freedom; ``iterations`` taken;
    ``head``: the self-calibrated ``(K_left, K_right, T_left_right, lens terms left, right)``
    (:data:`cell.referencing.survey.problem.Head`; None: held as given)."""

    points: Array
    poses: Array
    covariance: Array | None
    chi2: float
    dof: int
    iterations: int
    head: tuple[Array, Array, Array, Array, Array] | None = None
    #: the self-calibrated head's marginal covariances: each camera's Cal3DS2 (9, 9: fx, fy,
    #: skew, cx, cy, k1, k2, p1, p2) and the rig's Pose3 (6, 6: rotation, translation in its own
    #: frame); None: not computed
    head_covariance: tuple[Array, Array, Array] | None = None

    @property
    def variance_factor(self) -> float:
        """chi2 / dof: 1 when the stated pixel σ is right."""
        return self.chi2 / self.dof
