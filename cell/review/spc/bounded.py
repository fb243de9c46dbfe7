"""Capability of a position, a characteristic bounded below by zero, from a Rice fit.

A position value is 2 |d| with d the centre's in-plane deviation. When d is bivariate normal
with an offset nu and an isotropic sigma, |d| follows a Rice distribution (Rayleigh for a
centred process): skewed, bounded at 0, and its upper tail is longer than a normal one with
the same mean and s. The normal-theory Cpk = (USL - mean) / 3 sigma then misstates the
fraction beyond the zone. :func:`rice_cpk` fits Rice(nu, sigma) to the values (maximum
likelihood, ``scipy.stats.rice``, location 0) and returns the percentile index of
ISO 22514-2: Cpk = (USL - X50) / (X99.865 - X50), which equals the normal Cpk for normal data.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy import stats

#: the upper percentile of the ISO 22514-2 index (the normal mean + 3 sigma)
P_UPPER = 0.99865


@dataclass(frozen=True)
class RiceFit:
    """Rice fit of position values 2|d| (m): offset ``nu_m`` and ``sigma_m`` of |d|, the
    values' median and 99.865 % quantile, and the percentile Cpk against ``usl``."""

    nu_m: float
    sigma_m: float
    x50_m: float
    x99865_m: float
    cpk: float | None


def rice_cpk(values: Sequence[float], usl: float | None) -> RiceFit | None:
    """The Rice fit of ``values`` (position values, m) and its percentile Cpk; None when the
    values are too few (< 5) or do not spread."""
    v = np.asarray(values, float)
    scale = float(v.std())
    if len(v) < 5 or not scale > 0 or np.any(v < 0):
        return None
    r = v / 2.0 / scale  # |d| in units of the values' spread: a well-conditioned fit
    b, _loc, sig = stats.rice.fit(r, floc=0.0)
    x50, xu = 2.0 * scale * sig * stats.rice.ppf([0.5, P_UPPER], b)
    cpk = None if usl is None or not xu > x50 else float((usl - x50) / (xu - x50))
    return RiceFit(
        nu_m=float(b * sig * scale),
        sigma_m=float(sig * scale),
        x50_m=float(x50),
        x99865_m=float(xu),
        cpk=cpk,
    )
