"""The markers' centre noise the covariances are stated at.

The survey weights every marker centre by the stated ``sigma_px`` (0.05 px, the middle of the
published 0.02-0.1 px for circular targets). Its a posteriori standard deviation,
``sigma_px * sqrt(variance_factor)`` over thousands of observations, is what the detector
reached on these images; the network's covariance, the self-calibrated head's and each stop's
resection are stated at that figure, never below :data:`SIGMA_FLOOR_PX`: the best published
centre accuracy. The simulator's rendered images reach about 0.006 px, which no real print,
lens and sensor do; the floor keeps the stated uncertainty that of a real cell. When the
residuals are larger than stated the variance factor inflates the covariances as before.
"""

from __future__ import annotations

import math

#: the smallest marker-centre standard deviation the covariances are stated at (px)
SIGMA_FLOOR_PX = 0.02


def effective_sigma_px(stated_px: float, variance_factor: float) -> float:
    """The centre noise (px) the covariances are stated at (module doc)."""
    return max(stated_px * math.sqrt(max(variance_factor, 0.0)), SIGMA_FLOOR_PX)


def covariance_scale(stated_px: float, variance_factor: float) -> float:
    """The factor on a covariance computed at ``stated_px``: ``(effective / stated)^2``."""
    return (effective_sigma_px(stated_px, variance_factor) / stated_px) ** 2
