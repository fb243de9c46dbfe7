"""The arm's pose repeatability as a standard uncertainty of the TCP position.

Makers give the unidirectional pose repeatability RP of ISO 9283: over repeated approaches,
``RP = l_mean + 3 S_l`` with ``l`` the distance of each attained position from their barycentre.
For an isotropic Gaussian scatter with standard deviation ``s`` per axis, ``l`` follows a
Maxwell distribution (mean ``2 s sqrt(2/pi)``, standard deviation ``s sqrt(3 - 8/pi)``), so
``RP = 3.616 s`` and the standard uncertainty per axis is ``RP / 3.616``.

Defaults from ABB's product specifications (RP at rated load, ISO 9283): IRB 1600-10/1.45
0.02 mm, IRB 2600-20/1.65 0.04 mm, IRB 4600-60/2.05 0.05 mm (``robot.repeatability_m`` in the
cell file overrides them, e.g. with a figure measured on the cell's own arm).
"""

from __future__ import annotations

import math

#: ISO 9283 RP per built-in arm model (m)
DATASHEET_RP_M: dict[str, float] = {
    "abb_irb1600_10_145": 0.02e-3,
    "abb_irb2600_20_165": 0.04e-3,
    "abb_irb4600_60_205": 0.05e-3,
}
#: RP assumed for an arm that is not built in and has no cell-file figure (m): the largest above
FALLBACK_RP_M = 0.05e-3
#: RP / s for an isotropic 3-D Gaussian scatter with s per axis
RP_PER_SIGMA = 2.0 * math.sqrt(2.0 / math.pi) + 3.0 * math.sqrt(3.0 - 8.0 / math.pi)


def repeatability_rp_m(model: str, cell_figure_m: float | None) -> tuple[float, str]:
    """The RP to use (m) and where it came from (for the budget's note)."""
    if cell_figure_m is not None:
        return float(cell_figure_m), "cell file robot.repeatability_m"
    if model in DATASHEET_RP_M:
        return DATASHEET_RP_M[model], f"ABB data sheet RP of {model}"
    return FALLBACK_RP_M, f"no figure for {model}: {FALLBACK_RP_M * 1e3:.2f} mm RP assumed"


def sigma_per_axis_m(rp_m: float) -> float:
    """Standard uncertainty per axis (m) of a TCP position with ISO 9283 repeatability RP."""
    return float(rp_m) / RP_PER_SIGMA
