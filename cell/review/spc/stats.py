"""Individuals / moving-range (I-MR) statistics and capability of one characteristic.

Estimators (n values in run order, MR_i = |x_i - x_(i-1)|):
- ``s``: the overall sample standard deviation (ddof = 1);
- ``sigma_within``: the moving-range estimate MR-bar / d2 with d2 = 1.128 (subgroups of 2);
- control limits mean +- 3 sigma_within (individuals), 0 .. D4 MR-bar with D4 = 3.267 (MR);
- Cp = (USL - LSL) / 6 sigma_within, Cpk = min(USL - mean, mean - LSL) / 3 sigma_within
  (short-term capability), Pp / Ppk the same with ``s`` (overall performance);
- a one-sided characteristic (position: only an upper limit, its natural lower bound 0 is not
  a tolerance) has no Cp / Pp and Cpk = (USL - mean) / 3 sigma; its LCL is raised to 0.

Out-of-control rules (Nelson 1984, the first three; and the MR chart's limit):
1. a point beyond the 3-sigma limits; 2. nine points in a row on one side of the centre line;
3. six points in a row steadily increasing or decreasing; MR: a moving range above its UCL.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

D2 = 1.128
D4 = 3.267
RULES = {
    "beyond_3sigma": "point beyond the 3-sigma limits",
    "nine_same_side": "9 points in a row on one side of the centre line",
    "six_trend": "6 points in a row steadily increasing or decreasing",
    "mr_beyond_ucl": "moving range above its upper control limit",
}


@dataclass(frozen=True)
class Capability:
    """The I-MR statistics of one characteristic (units of the values: m)."""

    n: int
    mean: float
    s: float
    sigma_within: float
    mr_bar: float
    ucl: float
    lcl: float
    ucl_mr: float
    lsl: float | None
    usl: float | None
    cp: float | None
    cpk: float | None
    pp: float | None
    ppk: float | None
    #: run index (0-based, in the given order) -> the rules it broke
    out_of_control: dict[int, list[str]] = field(default_factory=dict)
    #: Cpk's approximate 95 % confidence interval (Bissell 1990); None without a Cpk
    cpk_ci95: tuple[float, float] | None = None

    @property
    def enough_for_capability(self) -> bool:
        """Whether ``n`` reaches :data:`MIN_CAPABILITY_N`: below it a capability index is
        indicative only (its interval says how little it is known)."""
        return self.n >= MIN_CAPABILITY_N

    def capability_note(self) -> str:
        """One line for a report, empty when there are enough values."""
        if self.enough_for_capability:
            return ""
        ci = (
            ""
            if self.cpk_ci95 is None
            else f" (Cpk 95 % interval {self.cpk_ci95[0]:.2f} to {self.cpk_ci95[1]:.2f})"
        )
        return (
            f"{self.n} runs, fewer than the {MIN_CAPABILITY_N} a capability study needs "
            f"({CAPABILITY_REFERENCE}): indicative only{ci}"
        )


#: the smallest number of individual values for a capability index (AIAG SPC manual, 2nd ed.,
#: and ISO 22514-2: at least 25 subgroups; for individuals, 25 values)
MIN_CAPABILITY_N = 25
CAPABILITY_REFERENCE = "AIAG SPC manual 2nd ed., ISO 22514-2"
#: the normal quantile of a two-sided 95 % interval
Z95 = 1.959963984540054


def cpk_interval(cpk: float, n: int) -> tuple[float, float]:
    """Bissell's (1990) approximate 95 % confidence interval of Cpk from ``n`` values:
    ``Cpk +- z sqrt(1/(9n) + Cpk^2/(2(n-1)))``."""
    half = Z95 * math.sqrt(1.0 / (9.0 * n) + cpk * cpk / (2.0 * (n - 1)))
    return cpk - half, cpk + half


def _index(lsl: float | None, usl: float | None, mean: float, sigma: float):
    """(Cp, Cpk) for ``sigma``; None where a limit is missing or sigma is zero."""
    if not sigma > 0 or (lsl is None and usl is None):
        return None, None
    cp = None if lsl is None or usl is None else (usl - lsl) / (6.0 * sigma)
    sides = [
        v
        for v in (
            (usl - mean) if usl is not None else None,
            (mean - lsl) if lsl is not None else None,
        )
        if v is not None
    ]
    return cp, min(sides) / (3.0 * sigma)


def _runs(flags: np.ndarray, length: int) -> np.ndarray:
    """Mark every index that ends a run of ``length`` consecutive True values."""
    out = np.zeros(len(flags), bool)
    count = 0
    for i, f in enumerate(flags):
        count = count + 1 if f else 0
        out[i] = count >= length
    return out


def out_of_control(
    x: np.ndarray, centre: float, lcl: float, ucl: float, ucl_mr: float
) -> dict[int, list[str]]:
    """Run index -> the rules (:data:`RULES` keys) it breaks."""
    hits: dict[int, list[str]] = {}

    def mark(mask: np.ndarray, rule: str) -> None:
        for i in np.flatnonzero(mask):
            hits.setdefault(int(i), []).append(rule)

    mark((x > ucl) | (x < lcl), "beyond_3sigma")
    mark(_runs(x > centre, 9) | _runs(x < centre, 9), "nine_same_side")
    d = np.diff(x)
    up, down = np.r_[False, _runs(d > 0, 5)], np.r_[False, _runs(d < 0, 5)]
    mark(up | down, "six_trend")
    mark(np.r_[False, np.abs(d) > ucl_mr], "mr_beyond_ucl")
    return hits


def capability(
    values: Sequence[float], lsl: float | None, usl: float | None, lower_bound: float | None = None
) -> Capability:
    """I-MR statistics and capability of ``values`` (run order) against ``lsl`` / ``usl``
    (either may be None: one-sided). ``lower_bound``: a natural bound of the values (0 for a
    position), below which the LCL is not drawn (it is raised to the bound). Needs two values
    or more."""
    x = np.asarray(values, float)
    if len(x) < 2:
        raise ValueError(f"{len(x)} value(s): statistics need two runs or more")
    mean, s = float(x.mean()), float(x.std(ddof=1))
    mr_bar = float(np.abs(np.diff(x)).mean())
    sigma = mr_bar / D2
    ucl, lcl, ucl_mr = mean + 3 * sigma, mean - 3 * sigma, D4 * mr_bar
    if lower_bound is not None:
        lcl = max(lcl, lower_bound)
    cp, cpk = _index(lsl, usl, mean, sigma)
    pp, ppk = _index(lsl, usl, mean, s)
    return Capability(
        n=len(x),
        mean=mean,
        s=s,
        sigma_within=sigma,
        mr_bar=mr_bar,
        ucl=ucl,
        lcl=lcl,
        ucl_mr=ucl_mr,
        lsl=lsl,
        usl=usl,
        cp=cp,
        cpk=cpk,
        pp=pp,
        ppk=ppk,
        out_of_control=out_of_control(x, mean, lcl, ucl, ucl_mr),
        cpk_ci95=None if cpk is None else cpk_interval(cpk, len(x)),
    )
