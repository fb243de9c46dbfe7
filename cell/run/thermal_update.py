"""The thermal update of a run: reference-target observations in, a thermal model out.

Each measured reference target gives one observation row (time, target, joints, sensor readings,
target position in the TCP frame), the format of :mod:`robots.thermal.observations`. After a
reference round the runner identifies a model from every row so far with
:func:`robots.thermal.identify.identify`; what the data cannot determine is refused there and
reported here. Sensors: six readings are taken as one sensor per joint (link i -> sensor i),
one reading as a sensor shared by every link; other counts are refused.

The reference temperatures (where the nominal D-H table holds) follow the rule of
``holecell thermal identify`` (:func:`robots.thermal.identify.reference_from_cold`): the
readings of the cold state, here those the controller reports as the first reference round
starts (before the arm moves), or else those of the round's earliest observation.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from cell.config import CellConfig
from robots import Arm
from robots.thermal.compensate import compensated_T_cell_tcp
from robots.thermal.errors import ThermalError
from robots.thermal.identify import IdentificationResult, identify
from robots.thermal.model import ThermalModel, ThermalSpec
from robots.thermal.observations import CellGeometry, Observations
from robots.transforms import invert


def sensor_spec(n_sensors: int, reference_c: float | Sequence[float]) -> ThermalSpec:
    """The sensor-to-link map (:meth:`ThermalSpec.mapped`) for ``n_sensors`` readings with the
    reference temperature(s) ``reference_c`` (degC; one for all or one per sensor): six sensors
    ``j1..j6`` one per link, or one shared sensor."""
    names = tuple(f"j{i}" for i in range(1, 7)) if n_sensors == 6 else (
        tuple(f"t{i}" for i in range(1, n_sensors + 1)))  # fmt: skip
    ref = np.broadcast_to(np.asarray(reference_c, float), (n_sensors,))
    return ThermalSpec.mapped(names, tuple(float(v) for v in ref))


#: smallest change of a reading (K) over the rows for a temperature model to be identifiable
MIN_SPREAD_K = 0.2

#: one observation: (time s, target id, joints rad, readings degC, target in TCP frame m, round)
Row = tuple[float, str, np.ndarray, np.ndarray, np.ndarray, int]


@dataclass
class ThermalUpdate:
    """Collects reference observations of a run and identifies the model from them."""

    cell: CellConfig
    arm: Arm
    rows: list[Row] = field(default_factory=list)
    cold_degC: tuple[float, ...] | None = None  # noqa: N815 (unit suffix)
    result: IdentificationResult | None = None
    refusal: str = ""

    def add(
        self,
        t_s: float,
        target: str,
        q: np.ndarray,
        temps: np.ndarray,
        p_tcp: np.ndarray,
        round_index: int = 0,
    ) -> None:
        """One observation of reference round ``round_index``: target ``target`` seen at
        ``p_tcp`` (m, TCP frame)."""
        self.rows.append(
            (
                float(t_s),
                target,
                np.asarray(q, float),
                np.asarray(temps, float),
                np.asarray(p_tcp, float),
                int(round_index),
            )
        )

    def reference_degC(self) -> tuple[float, ...]:
        """Per-sensor reading (degC) of the cold state: ``cold_degC`` (the readings as the first
        reference round starts) when known, else the earliest observation of the first round
        (the mean of the rows at that time), as
        :func:`robots.thermal.identify.reference_from_cold` takes it from a file."""
        if self.cold_degC is not None:
            return self.cold_degC
        first = min(r[5] for r in self.rows)
        t0 = min(r[0] for r in self.rows if r[5] == first)
        temps = np.array([r[3] for r in self.rows if r[5] == first and r[0] == t0])
        return tuple(float(v) for v in temps.mean(axis=0))

    def observations(self) -> Observations:
        """The rows so far as :class:`Observations`."""
        t, ids, q, temps, p, _ = zip(*self.rows, strict=True)
        spec = sensor_spec(len(temps[0]), self.reference_degC())
        return Observations(
            np.array(t),
            tuple(ids),
            np.array(q),
            np.array(temps),
            spec.sensor_names,
            np.array(p),
            source="run reference targets",
        )

    def temperature_spread_K(self) -> float:
        """Largest change of any sensor's reading over the rows so far (K)."""
        temps = np.array([r[3] for r in self.rows])
        return float(np.max(temps.max(axis=0) - temps.min(axis=0))) if len(temps) else 0.0

    def identify(self) -> ThermalModel | None:
        """Identify from every row so far; None (``refusal`` says why) if nothing identifiable."""
        if not self.rows:
            self.refusal = "no reference observations"
            return None
        spread = self.temperature_spread_K()
        if spread < MIN_SPREAD_K:
            rounds = len({r[5] for r in self.rows})
            self.refusal = (
                f"the reference targets were seen at a single temperature state ({rounds} "
                f"round(s), readings within {spread:.2f} K); identification needs rounds at "
                "different temperatures: more --reference-rounds, further apart "
                "(--reference-interval-s), or give a model with --thermal"
            )
            return None
        try:
            obs = self.observations()
            geometry = CellGeometry(
                self.arm.T_cell_base,
                self.arm.T_tool0_tcp,
                {r.id: np.asarray(r.position, float) for r in self.cell.reference_targets},
            )
            spec = sensor_spec(obs.temps_degC.shape[1], self.reference_degC())
            self.result = identify(
                obs, geometry, self.arm.dh, spec, robot_model=self.cell.robot.model
            )
        except ThermalError as exc:
            self.refusal = str(exc)
            return None
        self.refusal = ""
        return self.result.model

    def check(self, model: ThermalModel) -> float:
        """RMS (m) of measured minus predicted target positions in the TCP frame, every row."""
        targets = {r.id: np.asarray(r.position, float) for r in self.cell.reference_targets}
        err = []
        for _, target, q, temps, p_tcp, _ in self.rows:
            T_cell_tcp = compensated_T_cell_tcp(
                model, self.arm.T_cell_base, self.arm.T_tool0_tcp, q, temps
            )
            T_tcp_cell = invert(T_cell_tcp)
            pred = T_tcp_cell[:3, :3] @ targets[target] + T_tcp_cell[:3, 3]
            err.append(np.sum((p_tcp - pred) ** 2))
        return float(np.sqrt(np.mean(err)))
