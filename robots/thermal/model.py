"""The temperature error model on the D-H table.

Link ``i`` is D-H row ``i`` (1..6): its lengths ``a_i`` and ``d_i`` grow
linearly with the temperature of the sensor mapped to it,

    L_i(T) = L_i0 * (1 + k_i * (T_s(i) - T_ref,s(i))),

and, optionally, its joint offset drifts linearly, ``theta_i(T) = theta_i0 +
c_i * (T_s(i) - T_ref,s(i))``. ``k_i`` is in 1/K, ``c_i`` in rad/K,
temperatures in degrees Celsius (only differences matter). The nominal table
holds at the reference temperatures. For the ABB chains link 1 carries ``d1``
(base to the J2 axis) and ``a1``, link 2 ``a2``, link 3 ``a3``, link 4 ``d4``,
link 6 ``d6``; link 5 has no length.

Everything lives in the robot base frame: :func:`fk_rows` gives
``T_base_tool0`` for a table that differs from row to row.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from robots.dh import DHTable
from robots.thermal.errors import ThermalSpecError
from robots.thermal.spec import (
    LENGTH_TERMS,
    N_LINKS,
    OFFSET_TERMS,
    TERM_SCALE,
    TERM_UNIT,
    Array,
    ThermalSpec,
    coefficient_vectors,
    drifted_arrays,
    fk_rows,
    term_kind_and_link,
)
from robots.thermal.uncertainty import prediction_covariance

__all__ = [
    "LENGTH_TERMS",
    "N_LINKS",
    "OFFSET_TERMS",
    "TERM_SCALE",
    "TERM_UNIT",
    "ThermalModel",
    "ThermalSpec",
    "coefficient_vectors",
    "drifted_arrays",
    "fk_rows",
    "term_kind_and_link",
]


@dataclass(frozen=True)
class ThermalModel:
    """An identified temperature error model of one arm.

    Attributes:
        table: nominal D-H table, valid at the reference temperatures (m, rad).
        spec: sensors, their link map and the reference temperatures.
        coefficients: identified terms (``k_link*`` in 1/K, ``c_joint*`` in rad/K); others are zero.
        std: one-sigma uncertainty of each identified term (same units).
        refused: terms the data could not determine, with the reason.
        robot_model: name of the arm model the table came from.
        T_cell_base: robot base pose in the cell frame at identification (4x4).
        T_tool0_tcp: tool (TCP) pose relative to tool0 at identification (4x4).
        fit: summary figures of the identification (residual RMS in m, rank, condition, counts).
        covariance: covariance of the identified terms (n x n, SI units squared) in the order of
            ``coefficients``; None: only ``std`` is known (the diagonal).
    """

    table: DHTable
    spec: ThermalSpec
    coefficients: Mapping[str, float]
    std: Mapping[str, float] = field(default_factory=dict)
    refused: Mapping[str, str] = field(default_factory=dict)
    robot_model: str = ""
    T_cell_base: Array = field(default_factory=lambda: np.eye(4))
    T_tool0_tcp: Array = field(default_factory=lambda: np.eye(4))
    fit: Mapping[str, float] = field(default_factory=dict)
    covariance: Array | None = None

    def vectors(self) -> tuple[Array, Array]:
        """``(k (6,) 1/K, c (6,) rad/K)``."""
        return coefficient_vectors(self.coefficients)

    def arrays_at(self, temps_degC: ArrayLike) -> tuple[Array, Array, Array, Array]:
        """Compensated D-H arrays for sensor readings ``temps_degC`` (..., n_sensors)."""
        k, c = self.vectors()
        return drifted_arrays(self.table, k, c, self.spec.link_delta_K(temps_degC))

    def table_at(self, temps_degC: ArrayLike) -> DHTable:
        """The compensated D-H table for one set of sensor readings (degC)."""
        temps = np.asarray(temps_degC, dtype=float)
        if temps.ndim != 1:
            raise ThermalSpecError("temperatures", temps.shape, "one reading per sensor expected")
        a, d, _, theta = self.arrays_at(temps)
        return self.table.with_lengths(a, d).with_offsets(theta)

    def fk(self, q: ArrayLike, temps_degC: ArrayLike) -> Array:
        """Compensated ``T_base_tool0`` at joints ``q`` (..., 6) and readings (..., n_sensors)."""
        a, d, alpha, theta = self.arrays_at(temps_degC)
        return fk_rows(a, d, alpha, theta, self.table.joint_values(q))

    def predict_covariance(
        self,
        q: ArrayLike,
        temps_degC: ArrayLike,
        point_tcp_m: ArrayLike | None = None,
        T_cell_base: ArrayLike | None = None,
    ) -> Array:
        """Covariance (..., 3, 3) in m^2, cell frame, of the compensated position of a TCP-fixed
        point (default the TCP origin; ``point_tcp_m`` in the TCP frame, m) at joints ``q``
        (..., 6) rad and sensor readings ``temps_degC`` (..., n_sensors) degC, propagated from
        the terms' covariance (:func:`robots.thermal.uncertainty.prediction_covariance`).
        ``T_cell_base`` defaults to the model's own base pose."""
        return prediction_covariance(self, q, temps_degC, point_tcp_m, T_cell_base)
