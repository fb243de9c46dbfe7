"""The part's temperature and the correction of measured lengths to 20 degC (ISO 1).

A part measured at temperature ``t`` (degC) is larger than at the reference temperature of
ISO 1 (20 degC) by ``alpha * (t - 20)``. The part expands about its datum, the origin of the part
frame (where the fixture locates it), so a point measured at ``p_t`` (part frame, m) lies at

    p_20 = p_t / (1 + alpha (t - 20))

at 20 degC, and a diameter ``D_t`` is ``D_t / (1 + alpha (t - 20))``. The correction's standard
uncertainty, from the temperature's ``u_t`` (K) and the coefficient's ``u_alpha`` (1/K), is along
``p``: ``u(p_20) = |p_20| sqrt(alpha^2 u_t^2 + (t - 20)^2 u_alpha^2)``, the same for ``D``.

Where the temperature comes from, in this order: ``holecell run --part-temperature``, the cell
file's ``part.temperature_c``, else 20 degC assumed with ``ASSUMED_U_K`` (a shop held within
20 +- 5 degC, rectangular: 5 / sqrt(3) K), said so in every budget.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from cell.uncertainty.errors import PartTemperatureError
from cell.uncertainty.materials import Material

#: ISO 1 reference temperature (degC)
REFERENCE_C = 20.0
#: standard uncertainty of an unmeasured part's temperature (K): 20 +- 5 degC, rectangular
ASSUMED_U_K = 5.0 / math.sqrt(3.0)
#: standard uncertainty of a reading given without one (K): a contact thermometer on the part
DEFAULT_READING_U_K = 0.2
#: plausible readings (degC), as for the cell file
RANGE_C = (-10.0, 50.0)
#: standard uncertainty of the cell file's part.temperature_c given without one (K): a room figure
CELL_FILE_U_K = 1.0


@dataclass(frozen=True)
class PartThermalState:
    """The part's temperature (degC) and its standard uncertainty (K), the material, and where
    the temperature came from (``source``: "measured", "cell file" or "assumed")."""

    temperature_c: float
    u_temperature_K: float  # noqa: N815 (unit suffix)
    material: Material
    source: str
    material_from_cell: bool = True

    @property
    def delta_K(self) -> float:
        """Temperature above 20 degC (K)."""
        return self.temperature_c - REFERENCE_C

    @property
    def scale(self) -> float:
        """``1 + alpha (t - 20)``: lengths at ``t`` over lengths at 20 degC."""
        return 1.0 + self.material.alpha_per_K * self.delta_K

    def relative_u(self) -> float:
        """Relative standard uncertainty of the correction (unitless, per unit length)."""
        a, ua = self.material.alpha_per_K, self.material.u_alpha_per_K
        return math.hypot(a * self.u_temperature_K, self.delta_K * ua)

    def to_20c(self, p_part_m: np.ndarray) -> np.ndarray:
        """A point (part frame, m) or length measured at the part's temperature, at 20 degC."""
        return np.asarray(p_part_m, float) / self.scale

    def note(self) -> str:
        """One line for the budget: temperature, its origin, material."""
        mat = self.material
        src = {"measured": "measured", "cell file": "from the cell file (part.temperature_c)",
               "assumed": "not measured: 20 degC assumed (a shop within 20 +- 5 degC)"}  # fmt: skip
        where = src.get(self.source, self.source)
        m_note = "" if self.material_from_cell else " (part.material not given: steel assumed)"
        return (f"part at {self.temperature_c:.2f} degC +- {self.u_temperature_K:.2f} K, {where}; "
                f"{mat.name} alpha {mat.alpha_per_K * 1e6:.2f} +- {mat.u_alpha_per_K * 1e6:.2f} "
                f"ppm/K{m_note}")  # fmt: skip

    def to_dict(self) -> dict[str, object]:
        """JSON-ready mapping (degC, K, 1/K)."""
        return {
            "temperature_c": self.temperature_c,
            "u_temperature_K": self.u_temperature_K,
            "source": self.source,
            "material": self.material.name,
            "alpha_per_K": self.material.alpha_per_K,
            "u_alpha_per_K": self.material.u_alpha_per_K,
            "material_from_cell": self.material_from_cell,
        }

    @classmethod
    def from_dict(cls, d: dict) -> PartThermalState:
        """Inverse of :meth:`to_dict`."""
        mat = Material(str(d["material"]), float(d["alpha_per_K"]), float(d["u_alpha_per_K"]))
        return cls(float(d["temperature_c"]), float(d["u_temperature_K"]), mat,
                   str(d["source"]), bool(d.get("material_from_cell", True)))  # fmt: skip


def check_reading(value_c: float, u_K: float | None, source: str) -> None:
    """Refuse a reading outside the plausible range or a non-positive uncertainty."""
    if not (math.isfinite(value_c) and RANGE_C[0] <= value_c <= RANGE_C[1]):
        raise PartTemperatureError(
            source, value_c, f"a part temperature must be in [{RANGE_C[0]:g}, {RANGE_C[1]:g}] "
            "degC (a reading in kelvin or Fahrenheit?)")  # fmt: skip
    if u_K is not None and not (math.isfinite(u_K) and 0.0 < u_K <= 10.0):
        raise PartTemperatureError(source, u_K, "its uncertainty must be in (0, 10] K")


def part_state(cell, reading_c: float | None = None, u_reading_K: float | None = None,
               ) -> PartThermalState:  # fmt: skip
    """The part's thermal state for a run of ``cell`` (a :class:`cell.config.CellConfig`): the
    reading given to the run (``--part-temperature``), else the cell file's, else assumed."""
    material, named = cell.part_material()
    if reading_c is not None:
        check_reading(reading_c, u_reading_K, "--part-temperature")
        u = DEFAULT_READING_U_K if u_reading_K is None else u_reading_K
        return PartThermalState(float(reading_c), float(u), material, "measured", named)
    if cell.part.temperature_c is not None:
        u = cell.part.u_temperature_K or CELL_FILE_U_K
        return PartThermalState(cell.part.temperature_c, u, material, "cell file", named)
    return PartThermalState(REFERENCE_C, ASSUMED_U_K, material, "assumed", named)
