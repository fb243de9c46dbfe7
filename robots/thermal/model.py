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
from numpy.typing import ArrayLike, NDArray

from robots.dh import DHTable, fk_dh_arrays
from robots.thermal.errors import ThermalSpecError

Array = NDArray[np.float64]

N_LINKS = 6
LENGTH_TERMS: tuple[str, ...] = tuple(f"k_link{i}" for i in range(1, N_LINKS + 1))
OFFSET_TERMS: tuple[str, ...] = tuple(f"c_joint{i}" for i in range(1, N_LINKS + 1))
#: display scale of each term kind: 1e-6/K (ppm/K) for lengths, 1e-6 rad/K (urad/K) for offsets
TERM_SCALE: dict[str, float] = {"k": 1e-6, "c": 1e-6}
TERM_UNIT: dict[str, str] = {"k": "1/K", "c": "rad/K"}


def term_kind_and_link(name: str) -> tuple[str, int]:
    """``("k" | "c", link index 0..5)`` of a term name such as ``k_link2`` or ``c_joint3``."""
    for prefix, kind in (("k_link", "k"), ("c_joint", "c")):
        if name.startswith(prefix) and name[len(prefix) :].isdigit():
            link = int(name[len(prefix) :]) - 1
            if 0 <= link < N_LINKS:
                return kind, link
    raise ThermalSpecError("term", name, "unknown term; expected k_link1..6 or c_joint1..6")


@dataclass(frozen=True)
class ThermalSpec:
    """Which sensor drives which link, the reference temperatures and the terms to consider.

    Attributes:
        sensor_names: names of the temperature sensors, in file column order.
        sensor_of_link: for each of the six links, the index of its sensor.
        reference_degC: per sensor, the temperature at which the nominal D-H table holds (degC).
        lengths: consider the length coefficients ``k_link1..6`` (1/K).
        offsets: consider the joint-offset drifts ``c_joint1..6`` (rad/K).
    """

    sensor_names: tuple[str, ...]
    sensor_of_link: tuple[int, ...]
    reference_degC: tuple[float, ...]  # noqa: N815 (unit suffix)
    lengths: bool = True
    offsets: bool = False

    def __post_init__(self) -> None:
        if not self.sensor_names:
            raise ThermalSpecError("sensor_names", self.sensor_names, "at least one sensor needed")
        if len(set(self.sensor_names)) != len(self.sensor_names):
            raise ThermalSpecError("sensor_names", self.sensor_names, "sensor names repeat")
        if len(self.sensor_of_link) != N_LINKS:
            raise ThermalSpecError("sensor_of_link", self.sensor_of_link, "needs six entries")
        for s in self.sensor_of_link:
            if not 0 <= int(s) < len(self.sensor_names):
                raise ThermalSpecError(
                    "sensor_of_link", self.sensor_of_link, "sensor index out of range"
                )
        if len(self.reference_degC) != len(self.sensor_names):
            raise ThermalSpecError(
                "reference_degC", self.reference_degC, "one value per sensor needed"
            )
        if not np.all(np.isfinite(self.reference_degC)):
            raise ThermalSpecError("reference_degC", self.reference_degC, "values must be finite")
        if not (self.lengths or self.offsets):
            raise ThermalSpecError("terms", (self.lengths, self.offsets), "no term kind selected")

    def candidate_terms(self) -> tuple[str, ...]:
        """Every term this spec considers, before identifiability is checked."""
        return (LENGTH_TERMS if self.lengths else ()) + (OFFSET_TERMS if self.offsets else ())

    def link_delta_K(self, temps_degC: ArrayLike) -> Array:
        """Per-link rise over the reference (K), shape ``(..., 6)``, from sensor readings (degC)."""
        temps = np.asarray(temps_degC, dtype=float)
        if temps.shape[-1] != len(self.sensor_names):
            raise ThermalSpecError(
                "temperatures", temps.shape, f"expected {len(self.sensor_names)} sensor readings"
            )
        idx = np.asarray(self.sensor_of_link, dtype=int)
        return temps[..., idx] - np.asarray(self.reference_degC, dtype=float)[idx]

    @staticmethod
    def mapped(
        sensor_names: tuple[str, ...],
        reference_degC: tuple[float, ...],
        link_sensors: tuple[str, ...] | None = None,
        offsets: bool = False,
    ) -> ThermalSpec:
        """A spec: one sensor drives every link; six map in order; else give ``link_sensors``."""
        if link_sensors is None:
            if len(sensor_names) == 1:
                link_sensors = sensor_names * N_LINKS
            elif len(sensor_names) == N_LINKS:
                link_sensors = sensor_names
            else:
                raise ThermalSpecError(
                    "sensor map",
                    sensor_names,
                    "with neither one nor six sensors, say which sensor drives each link",
                )
        if len(link_sensors) != N_LINKS:
            raise ThermalSpecError(
                "sensor map", link_sensors, "needs six sensor names, one per link"
            )
        unknown = [s for s in link_sensors if s not in sensor_names]
        if unknown:
            raise ThermalSpecError(
                "sensor map", unknown, f"not among the sensors {list(sensor_names)}"
            )
        return ThermalSpec(
            sensor_names=tuple(sensor_names),
            sensor_of_link=tuple(sensor_names.index(s) for s in link_sensors),
            reference_degC=tuple(float(v) for v in reference_degC),
            offsets=offsets,
        )


def drifted_arrays(
    table: DHTable, k_per_K: ArrayLike, c_rad_per_K: ArrayLike, dT_link_K: ArrayLike
) -> tuple[Array, Array, Array, Array]:
    """D-H arrays ``(a, d, alpha, theta_offset)`` at per-link rises ``dT_link_K`` (..., 6).

    ``k_per_K`` (6,) scales the lengths of each link, ``c_rad_per_K`` (6,) drifts the joint offsets.
    ``a``, ``d`` and ``theta_offset`` have the shape of ``dT_link_K``; ``alpha`` is (6,).
    """
    a0, d0, alpha, off0 = table.arrays()
    dT = np.asarray(dT_link_K, dtype=float)
    scale = 1.0 + np.asarray(k_per_K, dtype=float) * dT
    theta = off0 + np.asarray(c_rad_per_K, dtype=float) * dT
    return a0 * scale, d0 * scale, alpha, theta


def fk_rows(a: Array, d: Array, alpha: Array, theta_offset: Array, q: ArrayLike) -> Array:
    """``T_base_tool0`` (..., 4, 4) for D-H arrays that may differ per row (as ``fk_dh``)."""
    return fk_dh_arrays(a, d, alpha, theta_offset, q)


def coefficient_vectors(coefficients: Mapping[str, float]) -> tuple[Array, Array]:
    """Full ``(k (6,) 1/K, c (6,) rad/K)`` from a term-to-value map; absent terms are zero."""
    k = np.zeros(N_LINKS)
    c = np.zeros(N_LINKS)
    for name, value in coefficients.items():
        kind, link = term_kind_and_link(name)
        (k if kind == "k" else c)[link] = float(value)
    return k, c


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
        from robots.thermal.uncertainty import prediction_covariance

        return prediction_covariance(self, q, temps_degC, point_tcp_m, T_cell_base)
