"""The simulated cell's hidden truth: its clock, the drifted kinematics and the true holes.

The runner never reads this module's state; it sees only what the controller reports over the
link (joints, temperatures) and what the cameras capture. The simulation clock runs ``speed``
times faster than the wall clock; the thermal drift is evaluated at ``drift_offset_s`` plus the
simulation time, so a run can start on a half-warm arm.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass

import numpy as np

from robots.thermal.drift import DriftSettings, DriftTruth, default_settings


class SimClock:
    """Simulation time: ``speed`` simulation seconds per wall second, from construction.

    The speed can change while running (:meth:`set_speed`, e.g. to fast-forward a warm-up), and
    the clock can be held (:meth:`held`) while the simulator computes something that takes no
    time in the real cell (rendering an exposure)."""

    def __init__(self, speed: float = 1.0) -> None:
        if not speed > 0:
            raise ValueError(f"speed {speed} must be > 0")
        self.speed = float(speed)
        self._base_sim = 0.0
        self._base_wall = time.monotonic()
        self._lock = threading.Lock()

    def now(self) -> float:
        """Simulation time (s) since the start."""
        with self._lock:
            return self._base_sim + (time.monotonic() - self._base_wall) * self.speed

    def set_speed(self, speed: float) -> None:
        """Change the speed from now on (simulation time stays continuous)."""
        if not speed > 0:
            raise ValueError(f"speed {speed} must be > 0")
        with self._lock:
            wall = time.monotonic()
            self._base_sim += (wall - self._base_wall) * self.speed
            self._base_wall, self.speed = wall, float(speed)

    @contextmanager
    def held(self) -> Iterator[None]:
        """Simulation time does not advance inside this block."""
        t = self.now()
        try:
            yield
        finally:
            with self._lock:
                self._base_sim, self._base_wall = t, time.monotonic()

    def wall_for(self, sim_s: float) -> float:
        """Wall seconds that ``sim_s`` simulation seconds take."""
        return sim_s / self.speed


@dataclass(frozen=True)
class TrueHole:
    """A hole as it really is (cell frame, m): centre, unit normal out of the surface, diameter."""

    id: str
    position_m: np.ndarray
    normal: np.ndarray
    diameter_m: float


@dataclass(frozen=True)
class WorldOptions:
    """Settings of the truth.

    Attributes:
        speed: simulation seconds per wall second (> 0).
        drift_offset_s: warm-up time already elapsed when the simulation starts (s).
        drift: the drift generator's settings (None: ``robots.thermal.drift.default_settings``).
        position_sigma_m: standard deviation of each true hole centre from nominal, in the
            surface plane (m): the part as machined.
        diameter_sigma_m: standard deviation of each true diameter from nominal (m; from the
            middle of its size limits where the cell gives them).
        seed: seed of the part errors and the sensor noise.
        repeatability_rp_m: the arm's ISO 9283 pose repeatability RP (m): every capture's TCP
            position scatters isotropically by ``RP / 3.616`` per axis (0: none).
        calibration_sigma_scale: the true stereo head differs from its calibration file by a
            draw of this many times the file's stated (or the default) uncertainties (0: the
            file is exact).
        part_temperature_c: the part's true temperature (degC); it expands about the part frame
            origin from its 20 degC geometry by ``part_alpha_per_K``.
        part_alpha_per_K: the part's true expansion coefficient (None: the cell's material
            figure).
        part_thermometer_sigma_K: standard deviation of a part temperature reading (K).
    """

    speed: float = 1.0
    drift_offset_s: float = 1800.0
    drift: DriftSettings | None = None
    position_sigma_m: float = 15e-6
    diameter_sigma_m: float = 5e-6
    seed: int = 0
    repeatability_rp_m: float = 0.0
    calibration_sigma_scale: float = 0.0
    part_temperature_c: float = 20.0
    part_alpha_per_K: float | None = None  # noqa: N815 (unit suffix)
    part_thermometer_sigma_K: float = 0.0  # noqa: N815 (unit suffix)


class SimWorld:
    """The truth of one simulated cell: built from a :class:`cell.config.CellConfig`."""

    def __init__(self, cell, options: WorldOptions | None = None) -> None:
        self.options = options or WorldOptions()
        self.clock = SimClock(self.options.speed)
        self.cell = cell
        self.arm = cell.build_arm()
        self.T_cell_base = np.asarray(cell.T_cell_base(), dtype=float)
        self.T_tool0_tcp = np.asarray(cell.T_tool0_tcp(), dtype=float)
        settings = self.options.drift or default_settings()
        self.drift = DriftTruth(self.arm.dh, settings, seed=self.options.seed)
        self.holes = self._true_holes(np.random.default_rng(self.options.seed))
        o = self.options
        self.part_alpha_per_K = (cell.part_material()[0].alpha_per_K
                                 if o.part_alpha_per_K is None else o.part_alpha_per_K)  # fmt: skip
        self.holes_at_temperature = self._expanded(self.holes)

    def _expanded(self, holes: dict[str, TrueHole]) -> dict[str, TrueHole]:
        """The true holes as they are at the part's temperature: the 20 degC geometry expanded
        about the part frame origin (cell frame, m)."""
        s = 1.0 + self.part_alpha_per_K * (self.options.part_temperature_c - 20.0)
        T = np.asarray(self.cell.T_cell_part(), float)
        out = {}
        for k, h in holes.items():
            p_part = T[:3, :3].T @ (h.position_m - T[:3, 3])
            out[k] = TrueHole(h.id, T[:3, :3] @ (s * p_part) + T[:3, 3], h.normal, s * h.diameter_m)
        return out

    def part_reading_c(self) -> float:
        """A reading of the part's temperature (degC): the truth plus the thermometer's noise."""
        rng = np.random.default_rng([self.options.seed, 0x7A27])
        return float(self.options.part_temperature_c
                     + rng.normal(0.0, self.options.part_thermometer_sigma_K))  # fmt: skip

    def _true_holes(self, rng: np.random.Generator) -> dict[str, TrueHole]:
        out: dict[str, TrueHole] = {}
        # the machining process aims at the middle of a hole's size limits (cell.gdt)
        sizes = {h.id: h.tolerances.size for h in self.cell.part.holes
                 if h.tolerances is not None and h.tolerances.size is not None}  # fmt: skip
        for h in self.cell.holes_in_cell():
            n = np.asarray(h.normal, dtype=float)
            u = np.cross(n, [1.0, 0.0, 0.0] if abs(n[0]) < 0.9 else [0.0, 1.0, 0.0])
            u /= np.linalg.norm(u)
            v = np.cross(n, u)
            du, dv = rng.normal(0.0, self.options.position_sigma_m, 2)
            size = sizes.get(h.id)
            mid = 0.0 if size is None else (size.upper_m + size.lower_m) / 2.0
            dd = mid + rng.normal(0.0, self.options.diameter_sigma_m)
            out[h.id] = TrueHole(
                h.id, np.asarray(h.position_m, float) + du * u + dv * v, n, h.diameter_m + dd
            )
        return out

    def temperatures(self, t_s: float) -> np.ndarray:
        """What the controller's sensors read (degC) at simulation time ``t_s``."""
        return np.asarray(self.drift.sensor_readings(self.options.drift_offset_s + t_s), float)

    def sensor_names(self) -> tuple[str, ...]:
        """Names of the temperature sensors, in the order STATUS reports them."""
        return self.drift.settings.sensor_names

    def true_T_cell_tcp(self, q_rad: np.ndarray, t_s: float) -> np.ndarray:
        """The true (drifted) TCP pose in the cell at joints ``q_rad`` and time ``t_s``."""
        t_drift = self.options.drift_offset_s + t_s
        T_base_tool0 = self.drift.T_base_tool0(np.asarray(q_rad, float), t_drift)
        return self.T_cell_base @ T_base_tool0 @ self.T_tool0_tcp
