"""The markers' centre noise the survey weighs its observations with and states its covariances
at (variance component estimation).

The survey first adjusts with the stated ``sigma_px`` (0.05 px, the middle of the published
0.02-0.1 px for circular targets): it finds the outliers at 5 sigma of that figure. Its a
posteriori standard deviation over thousands of observations, ``sigma_px * sqrt(variance
factor)``, is what the detector reached on these images. The final adjustment then weighs the
image observations at that figure, never below the floor (``sigma_floor_px``), while the scale
bars and the head's priors keep their own stated sigma; its covariance is the network's,
inflated only when the residuals still exceed the weights (variance factor above 1).

Why not scale a covariance computed at the stated 0.05 px: that scales the scale bars' and the
head priors' information with the pixels'. On clean images (0.006 px, 1/8 of the stated) the
bars' 2.5 um then read as 0.3 um, and the markers' stated sigma missed their true error (84-91 %
of the coordinates within 2 sigma through rendered images, 83-87 % on simulated detections at
0.006 px; 92-99 % weighted at the true noise; docs/referencing.md).

The floor: :data:`SIGMA_FLOOR_PX`, the best published target-centre accuracy, is what a real head
states (a real print, lens, sensor and air do not reach the simulator's 0.006 px, and part of
their error is common to the views and does not show in the residuals). The simulated head
states its own (:mod:`cell.demo.survey`).
"""

from __future__ import annotations

import math

#: the smallest marker-centre standard deviation a real head's covariances are stated at (px)
SIGMA_FLOOR_PX = 0.02


def effective_sigma_px(
    stated_px: float, variance_factor: float, floor_px: float = SIGMA_FLOOR_PX
) -> float:
    """The centre noise (px) the final adjustment weighs with: the a posteriori figure
    ``stated_px * sqrt(variance_factor)``, not below ``floor_px`` (module doc)."""
    return max(stated_px * math.sqrt(max(variance_factor, 0.0)), floor_px)
