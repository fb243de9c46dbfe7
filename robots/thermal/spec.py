"""The temperature error model's terms and its sensor map (:mod:`robots.thermal.model`).

Link ``i`` is D-H row ``i`` (1..6): its lengths grow with ``k_link<i>`` (1/K) times the rise of
its sensor over the reference, its joint offset drifts with ``c_joint<i>`` (rad/K).
:class:`ThermalSpec` says which sensor drives which link and at what reference temperatures
(degC) the nominal table holds; :func:`drifted_arrays` and :func:`fk_rows` give the drifted
D-H arrays and ``T_base_tool0`` for them.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

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
