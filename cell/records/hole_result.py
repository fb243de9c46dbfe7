"""The result of inspecting one hole: what the store keeps and the report shows.

Frames and units: ``*_part_m`` in the part frame (m); ``normal_part`` unit axis out of the
surface; deviations in m; ``q_rad`` joints at capture (rad); ``temperatures_c`` sensor readings
(degC); times in s. ``status`` is ``"ok"`` (measured, within tolerance or no tolerance),
``"fail"`` (measured, out of tolerance), ``"suspect"`` (measured, but the measurement flags much
filled or rejected edge: a quality flag, whatever the deviations), ``"missing"`` (no hole where
one should be; no measured values) or ``"unmeasured"`` (a hole was seen but could not be measured;
no measured values; a resumed run tries it again). ``passed`` is the verdict against the
tolerance from the deviations alone (True / False), None when the hole was not measured; a
suspect hole keeps it.
Positions and diameters are at 20 degC (ISO 1: corrected for the part's temperature);
``position_deviation_m`` is the centre's distance from the nominal in the plane perpendicular to
the nominal axis, ``axial_deviation_m`` the signed offset along it (out of the surface).
``U_position_m`` / ``U_diameter_m`` are the expanded uncertainties (k = 2) of the budget
``budget`` (:class:`cell.uncertainty.budget.HoleBudget` as a mapping), ``decision`` the ISO
14253-1 decision (``conforming`` / ``inconclusive`` / ``nonconforming``; None when not measured
or without a tolerance) under ``decision_rule``.
``thermal_model_id`` names the thermal model (row of the store's ``thermal_models``) the pose was
compensated with; None: the nominal kinematics.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np

STATUSES = ("ok", "fail", "suspect", "missing", "unmeasured")


@dataclass(frozen=True)
class HoleResult:
    """One hole, measured (or found missing) at one stop of a run."""

    hole_id: str
    stop_index: int
    status: str
    nominal_part_m: tuple[float, float, float]
    nominal_diameter_m: float
    tolerance_m: float | None
    center_part_m: tuple[float, float, float] | None = None
    normal_part: tuple[float, float, float] | None = None
    diameter_m: float | None = None
    position_deviation_m: float | None = None
    diameter_deviation_m: float | None = None
    u_center_m: float | None = None
    u_diameter_m: float | None = None
    rms_m: float | None = None
    n_points: int | None = None
    q_rad: tuple[float, ...] = ()
    temperatures_c: tuple[float, ...] = ()
    sim_time_s: float = 0.0
    measure_time_s: float = 0.0
    reason: str = ""
    passed: bool | None = None
    thermal_model_id: int | None = None
    extra: dict[str, Any] = field(default_factory=dict)
    axial_deviation_m: float | None = None
    U_position_m: float | None = None
    U_diameter_m: float | None = None
    decision: str | None = None
    decision_rule: str | None = None
    budget: dict[str, Any] | None = None

    def __post_init__(self) -> None:
        if self.status not in STATUSES:
            raise ValueError(f"status {self.status!r} not in {STATUSES}")

    @property
    def measured(self) -> bool:
        """True if the hole was found and measured."""
        return self.center_part_m is not None

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready mapping (SI units)."""
        return asdict(self)


def deviations(
    center_part_m: np.ndarray,
    diameter_m: float,
    nominal_part_m: np.ndarray,
    nominal_diameter_m: float,
    tolerance_m: float | None,
    normal_part: np.ndarray | None = None,
) -> tuple[float, float, bool, float]:
    """(position deviation (m), diameter deviation (m), pass, axial deviation (m)). The position
    deviation is the distance in the plane perpendicular to the nominal axis ``normal_part``
    (the full distance without one; axial then 0). A hole passes when both the position
    deviation and the absolute diameter deviation are within ``tolerance_m`` (always, if the
    hole has no tolerance)."""
    delta = np.asarray(center_part_m, float) - np.asarray(nominal_part_m, float)
    axial = 0.0
    if normal_part is not None:
        n = np.asarray(normal_part, float) / np.linalg.norm(normal_part)
        axial = float(delta @ n)
        delta = delta - axial * n
    dpos = float(np.linalg.norm(delta))
    ddia = float(diameter_m - nominal_diameter_m)
    ok = tolerance_m is None or (dpos <= tolerance_m and abs(ddia) <= tolerance_m)
    return dpos, ddia, ok, axial
