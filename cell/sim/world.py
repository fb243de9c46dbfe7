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
from dataclasses import dataclass, field, replace

import numpy as np

from cell.camera import cell_stereo
from cell.referencing.synthetic import MarkerTruth, draw_marker_truth
from cell.sim.true_geometry import TrueGeometry
from cell.sim.truth import CellTruth
from measure import StereoCalibration, head_frame
from robots.thermal.drift import DriftSettings, DriftTruth, default_settings
from robots.transforms import invert


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
    """Settings of the simulation; the cell's hidden errors are in ``truth``.

    Attributes:
        speed: simulation seconds per wall second (> 0).
        drift_offset_s: warm-up time already elapsed when the simulation starts (s).
        drift: the drift generator's settings (None: ``robots.thermal.drift.default_settings``).
        truth: every hidden error of the cell (:class:`cell.sim.truth.CellTruth`: D-H, base,
            head, part placement, target placement, the part as machined, repeatability, the
            head's calibration error, the part's temperature, the seed of every draw); default
            :meth:`CellTruth.zero`.
        part_alpha_per_K: the part's true expansion coefficient (None: the cell's material
            figure); the part expands about its true frame's origin.
        part_thermometer_sigma_K: standard deviation of a part temperature reading (K).
    """

    speed: float = 1.0
    drift_offset_s: float = 1800.0
    drift: DriftSettings | None = None
    truth: CellTruth = field(default_factory=CellTruth.zero)
    part_alpha_per_K: float | None = None  # noqa: N815 (unit suffix)
    part_thermometer_sigma_K: float = 0.0  # noqa: N815 (unit suffix)

    @property
    def seed(self) -> int:
        """The truth's seed: the part errors, the sensor noise, the head's draw."""
        return self.truth.seed


class SimWorld:
    """The truth of one simulated cell: built from a :class:`cell.config.CellConfig`.

    The true kinematics are the nominal D-H table plus ``truth.dh_errors`` under the thermal
    drift; the true base, head and part are the nominal poses composed with the truth's errors;
    the true holes are the nominal ones carried by the true part frame, then off by the part's
    machining scatter."""

    def __init__(self, cell, options: WorldOptions | None = None) -> None:
        self.options = options or WorldOptions()
        self.truth = self.options.truth
        self.clock = SimClock(self.options.speed)
        self.cell = cell
        self.arm = cell.build_arm()
        tr = self.truth
        self.T_cell_base = np.asarray(cell.T_cell_base(), dtype=float) @ tr.base_error
        self.T_tool0_tcp = np.asarray(cell.T_tool0_tcp(), dtype=float) @ tr.tcp_error
        self.T_cell_part = np.asarray(cell.T_cell_part(), dtype=float) @ tr.part_placement_error
        target = cell.calibration_target
        self.T_cell_target = (None if target is None
                              else target.T_cell_target() @ tr.target_placement_error)  # fmt: skip
        settings = self.options.drift or default_settings()
        self.drift = DriftTruth(tr.table(self.arm.dh), settings, seed=tr.seed)
        self.holes = self._true_holes(np.random.default_rng(tr.seed))
        o = self.options
        self.part_alpha_per_K = (cell.part_material()[0].alpha_per_K
                                 if o.part_alpha_per_K is None else o.part_alpha_per_K)  # fmt: skip
        self.holes_at_temperature = self._expanded(self.holes)
        self.markers = self._true_markers()

    def true_geometry(self, stereo: StereoCalibration | None = None) -> TrueGeometry:
        """The true frames (for the simulated head and benchmarks; never for the runner);
        ``stereo`` places the left camera in the head (None: the cell's calibration)."""
        stereo = stereo if stereo is not None else cell_stereo(self.cell)
        return TrueGeometry(self.drift.table, self.drift, self.options.drift_offset_s,
                            self.T_cell_base, self.T_tool0_tcp, invert(head_frame(stereo)),
                            self.T_cell_part, self.T_cell_target)  # fmt: skip

    def _expanded(self, holes: dict[str, TrueHole]) -> dict[str, TrueHole]:
        """The true holes as they are at the part's temperature: the 20 degC geometry expanded
        about the true part frame origin (cell frame, m)."""
        s = 1.0 + self.part_alpha_per_K * (self.truth.part_temperature_c - 20.0)
        T = self.T_cell_part
        out = {}
        for k, h in holes.items():
            p_part = T[:3, :3].T @ (h.position_m - T[:3, 3])
            out[k] = TrueHole(h.id, T[:3, :3] @ (s * p_part) + T[:3, 3], h.normal, s * h.diameter_m)
        return out

    def _true_markers(self) -> MarkerTruth | None:
        """The reference markers as they are (cell frame, m; None: the cell has none): off
        their nominal by the truth's draw or offsets; those on the part carried by its true
        placement and expanded with it about its true frame's origin."""
        if not self.cell.reference_markers:
            return None
        tr = self.truth
        mt = draw_marker_truth(self.cell, tr.seed, tr.marker_position_sigma_m,
                               tr.part_placement_error, tr.marker_errors)  # fmt: skip
        s = 1.0 + self.part_alpha_per_K * (tr.part_temperature_c - 20.0)
        T = self.T_cell_part
        p_part = (mt.true - T[:3, 3]) @ T[:3, :3]
        grown = np.where(mt.on_fixture[:, None], mt.true, (s * p_part) @ T[:3, :3].T + T[:3, 3])
        return replace(mt, true=grown)

    def part_reading_c(self) -> float:
        """A reading of the part's temperature (degC): the truth plus the thermometer's noise."""
        rng = np.random.default_rng([self.truth.seed, 0x7A27])
        return float(self.truth.part_temperature_c
                     + rng.normal(0.0, self.options.part_thermometer_sigma_K))  # fmt: skip

    def _true_holes(self, rng: np.random.Generator) -> dict[str, TrueHole]:
        out: dict[str, TrueHole] = {}
        T = self.T_cell_part
        for h in self.cell.part.holes:
            # the machining process aims at the middle of a hole's size limits (cell.gdt)
            size = None if h.tolerances is None else h.tolerances.size
            mid = 0.0 if size is None else (size.upper_m + size.lower_m) / 2.0
            p = T[:3, :3] @ np.array(h.position) + T[:3, 3]
            n = T[:3, :3] @ np.array(h.normal)
            u = np.cross(n, [1.0, 0.0, 0.0] if abs(n[0]) < 0.9 else [0.0, 1.0, 0.0])
            u /= np.linalg.norm(u)
            v = np.cross(n, u)
            du, dv = rng.normal(0.0, self.truth.hole_position_sigma_m, 2)
            dd = mid + rng.normal(0.0, self.truth.hole_diameter_sigma_m)
            out[h.id] = TrueHole(h.id, p + du * u + dv * v, n, h.diameter + dd)
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
