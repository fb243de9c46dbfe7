"""A thermal drift generator: the hidden truth for the cell simulator and the tests.

Each link warms along a first-order curve ``T(t) = T_amb + rise * (1 - exp(-t / tau))``
and lengthens by its material's expansion coefficient; each temperature sensor
the controller reports follows its own first-order curve (in the matched case
the same as its link's, in a mismatch case not). The truth also may carry joint
offset drifts. The thermal model never reads any of this: it only sees the
sensor readings and the stereo measurements.

Time in s, temperatures in degC, lengths in m, angles in rad. ``T_base_tool0``
is the true drifted forward kinematics in the robot base frame.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robots.dh import DHTable
from robots.thermal.errors import ThermalSpecError
from robots.thermal.model import N_LINKS, drifted_arrays, fk_rows

Array = NDArray[np.float64]

#: linear expansion coefficients (1/K)
MATERIAL_EXPANSION_PER_K: dict[str, float] = {
    "aluminium": 23e-6,
    "steel": 12e-6,
    "cast_iron": 10e-6,
}


@dataclass(frozen=True)
class WarmUp:
    """A first-order warm-up curve: ``rise_K * (1 - exp(-t / tau_s))`` above ambient."""

    rise_K: float  # noqa: N815 (unit suffix)
    tau_s: float

    def __post_init__(self) -> None:
        if not (np.isfinite(self.rise_K) and np.isfinite(self.tau_s) and self.tau_s > 0):
            raise ThermalSpecError(
                "warm-up", (self.rise_K, self.tau_s), "need a finite rise, tau > 0 s"
            )

    def rise_at(self, t_s: ArrayLike) -> Array:
        """Temperature rise (K) at times ``t_s`` (s); zero before t = 0."""
        t = np.maximum(np.asarray(t_s, dtype=float), 0.0)
        return self.rise_K * (1.0 - np.exp(-t / self.tau_s))


@dataclass(frozen=True)
class DriftSettings:
    """Settings of the drift truth.

    Attributes:
        materials: material of each of the six links (keys of ``MATERIAL_EXPANSION_PER_K``).
        link_warmup: warm-up curve of each link's true temperature.
        sensor_names: names of the temperature sensors the controller reports.
        sensor_warmup: warm-up curve of each sensor's reading.
        ambient_degC: temperature of the cold arm and of the hall at t = 0 (degC).
        sensor_noise_K: standard deviation of each sensor reading (K).
        offset_drift_rad_per_K: true joint offset drift per K of the link's rise (rad/K).
    """

    materials: tuple[str, ...]
    link_warmup: tuple[WarmUp, ...]
    sensor_names: tuple[str, ...]
    sensor_warmup: tuple[WarmUp, ...]
    ambient_degC: float = 20.0  # noqa: N815 (unit suffix)
    sensor_noise_K: float = 0.0  # noqa: N815 (unit suffix)
    offset_drift_rad_per_K: tuple[float, ...] = (0.0,) * N_LINKS  # noqa: N815 (unit suffix)

    def __post_init__(self) -> None:
        if len(self.materials) != N_LINKS or len(self.link_warmup) != N_LINKS:
            raise ThermalSpecError("materials/link_warmup", self.materials, "six links needed")
        unknown = [m for m in self.materials if m not in MATERIAL_EXPANSION_PER_K]
        if unknown:
            raise ThermalSpecError(
                "materials", unknown, f"known materials: {sorted(MATERIAL_EXPANSION_PER_K)}"
            )
        if len(self.sensor_names) != len(self.sensor_warmup) or not self.sensor_names:
            raise ThermalSpecError(
                "sensors", self.sensor_names, "one warm-up curve per sensor needed"
            )
        if len(self.offset_drift_rad_per_K) != N_LINKS:
            raise ThermalSpecError(
                "offset_drift_rad_per_K", self.offset_drift_rad_per_K, "six values"
            )
        if self.sensor_noise_K < 0:
            raise ThermalSpecError("sensor_noise_K", self.sensor_noise_K, "must be >= 0")

    @staticmethod
    def per_joint(
        materials: tuple[str, ...],
        link_warmup: tuple[WarmUp, ...],
        sensor_noise_K: float = 0.0,
        ambient_degC: float = 20.0,
        offset_drift_rad_per_K: tuple[float, ...] = (0.0,) * N_LINKS,
    ) -> DriftSettings:
        """Six sensors ``j1..j6`` that read their link's true temperature (plus noise)."""
        return DriftSettings(
            materials=materials,
            link_warmup=link_warmup,
            sensor_names=tuple(f"j{i}" for i in range(1, N_LINKS + 1)),
            sensor_warmup=link_warmup,
            ambient_degC=ambient_degC,
            sensor_noise_K=sensor_noise_K,
            offset_drift_rad_per_K=offset_drift_rad_per_K,
        )


class DriftTruth:
    """The true thermal state of an arm over time, and its true drifted kinematics."""

    def __init__(self, table: DHTable, settings: DriftSettings, seed: int = 0) -> None:
        self.table = table
        self.settings = settings
        self._rng = np.random.default_rng(seed)

    @property
    def expansion_per_K(self) -> Array:
        """True linear expansion coefficient of each link (1/K), shape (6,)."""
        return np.array([MATERIAL_EXPANSION_PER_K[m] for m in self.settings.materials])

    def link_rise_K(self, t_s: ArrayLike) -> Array:
        """True rise of each link over ambient (K), shape ``(..., 6)``."""
        t = np.asarray(t_s, dtype=float)
        return np.stack([w.rise_at(t) for w in self.settings.link_warmup], axis=-1)

    def link_temperatures(self, t_s: ArrayLike) -> Array:
        """True link temperatures (degC) at times ``t_s``, shape ``(..., 6)``."""
        return self.settings.ambient_degC + self.link_rise_K(t_s)

    def sensor_readings(self, t_s: ArrayLike, noisy: bool = True) -> Array:
        """What the controller reports (degC) at times ``t_s``, shape ``(..., n_sensors)``."""
        t = np.asarray(t_s, dtype=float)
        s = self.settings
        out = s.ambient_degC + np.stack([w.rise_at(t) for w in s.sensor_warmup], axis=-1)
        if noisy and s.sensor_noise_K > 0:
            out = out + self._rng.normal(0.0, s.sensor_noise_K, out.shape)
        return out

    def table_at(self, t_s: float) -> DHTable:
        """The true D-H table at one time (s)."""
        a, d, _, theta = drifted_arrays(
            self.table,
            self.expansion_per_K,
            self.settings.offset_drift_rad_per_K,
            self.link_rise_K(float(t_s)),
        )
        return self.table.with_lengths(a, d).with_offsets(theta)

    def T_base_tool0(self, q: ArrayLike, t_s: ArrayLike) -> Array:
        """True drifted ``T_base_tool0`` for joints ``q`` (..., 6) at times ``t_s`` (broadcast)."""
        a, d, alpha, theta = drifted_arrays(
            self.table,
            self.expansion_per_K,
            self.settings.offset_drift_rad_per_K,
            self.link_rise_K(t_s),
        )
        return fk_rows(a, d, alpha, theta, self.table.joint_values(q))


def default_settings(per_joint_noise_K: float = 0.05) -> DriftSettings:
    """The reference warm-up: two hours to about +15 K, aluminium arm links, steel wrist."""
    return DriftSettings.per_joint(
        materials=("cast_iron", "aluminium", "steel", "aluminium", "steel", "steel"),
        link_warmup=(
            WarmUp(8.0, 3600.0),
            WarmUp(15.0, 2400.0),
            WarmUp(13.0, 2000.0),
            WarmUp(15.0, 1800.0),
            WarmUp(12.0, 1500.0),
            WarmUp(10.0, 1500.0),
        ),
        sensor_noise_K=per_joint_noise_K,
    )
