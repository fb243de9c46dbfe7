"""The uncertainty budget of one hole (GUM, JCGM 100:2008).

Two measurands per hole, both at 20 degC in the part frame:

- the **position deviation** ``d = |P (c - c_nom)|``: the distance of the measured centre from
  the nominal in the plane perpendicular to the nominal axis (``P = I - n n^T``), as a CMM
  reports a hole's position;
- the **diameter** ``D`` (its deviation ``D - D_nom`` has the same uncertainty).

Each component gives a 3x3 covariance of the centre (part frame, m^2) and a variance of the
diameter (m^2); they are independent and add. The position deviation's standard uncertainty is
``g^T S g`` with ``g = P (c - c_nom) / d`` (first order), plus the second-order term of GUM
5.1.2 (``tr(H S H S) / 2`` with ``H = (P - g g^T) / d``, significant when ``d`` is not large
against the centre's scatter), the whole bounded by ``tr(P S P)`` (``|d - d_true|`` never
exceeds the in-plane error). ``U = k u`` with ``k = 2``.

Components (names as stored): ``circle_fit`` (the fit's covariance), ``stereo_calibration``
(:mod:`cell.uncertainty.calibration`), ``thermal_model`` (:mod:`cell.uncertainty.thermal`),
``robot_repeatability`` (:mod:`cell.uncertainty.repeatability`), ``part_temperature``
(:mod:`cell.uncertainty.part_temperature`), ``cell_calibration`` (a run with ``--calibration``:
the hand-eye and D-H terms' joint covariance carried to the hole's centre, first order,
:meth:`cell.calibration.use.run_calibration.RunGeometry.point_covariance_cell`; without one the
cell file's kinematics, base and head mount are taken as exact and the row is absent),
``resection`` and ``survey_markers`` (a stop located against the surveyed markers, in place of
the thermal model, the repeatability and the cell calibration: :mod:`cell.run.referenced`), and
``nonlinearity`` (the second-order term).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

#: coverage factor of the expanded uncertainty (about 95 % for a normal distribution)
K_COVERAGE = 2.0
COMPONENTS = ("circle_fit", "stereo_calibration", "thermal_model", "robot_repeatability",
              "part_temperature", "cell_calibration", "resection", "survey_markers",
              "nonlinearity")  # fmt: skip


@dataclass(frozen=True)
class Contribution:
    """One component before projection: centre covariance (3x3, part frame, m^2), diameter
    variance (m^2) and a note on where its figures came from."""

    name: str
    cov_center_m2: np.ndarray
    var_diameter_m2: float
    note: str = ""


@dataclass(frozen=True)
class Component:
    """One row of a budget: standard uncertainties (m) of the position deviation and of the
    diameter, and the note."""

    name: str
    u_position_m: float
    u_diameter_m: float
    note: str = ""


@dataclass(frozen=True)
class HoleBudget:
    """A hole's budget: components, combined standard and expanded (``k``) uncertainties (m)."""

    components: tuple[Component, ...]
    u_position_m: float
    u_diameter_m: float
    k: float = K_COVERAGE
    notes: tuple[str, ...] = field(default_factory=tuple)

    @property
    def U_position_m(self) -> float:
        """Expanded uncertainty of the position deviation (m)."""
        return self.k * self.u_position_m

    @property
    def U_diameter_m(self) -> float:
        """Expanded uncertainty of the diameter (m)."""
        return self.k * self.u_diameter_m

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready mapping (m)."""
        return {
            "k": self.k,
            "u_position_m": self.u_position_m,
            "u_diameter_m": self.u_diameter_m,
            "U_position_m": self.U_position_m,
            "U_diameter_m": self.U_diameter_m,
            "components": [vars(c).copy() for c in self.components],
            "notes": list(self.notes),
        }

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> HoleBudget:
        """Inverse of :meth:`to_dict`."""
        comps = tuple(Component(**c) for c in d["components"])
        return cls(comps, float(d["u_position_m"]), float(d["u_diameter_m"]), float(d["k"]),
                   tuple(d.get("notes", ())))  # fmt: skip


def in_plane(delta_part_m: np.ndarray, normal_part: np.ndarray) -> tuple[float, np.ndarray]:
    """The in-plane deviation ``d`` (m) and the projector ``P`` (3x3) of a nominal axis."""
    n = np.asarray(normal_part, float)
    n = n / np.linalg.norm(n)
    P = np.eye(3) - np.outer(n, n)
    return float(np.linalg.norm(P @ np.asarray(delta_part_m, float))), P


def combine(
    contributions: list[Contribution],
    delta_part_m: np.ndarray,
    normal_part: np.ndarray,
    notes: tuple[str, ...] = (),
    k: float = K_COVERAGE,
) -> HoleBudget:
    """The budget of a hole whose centre is ``delta_part_m`` off its nominal (part frame, m,
    at 20 degC), nominal axis ``normal_part``."""
    d, P = in_plane(delta_part_m, normal_part)
    S = sum((c.cov_center_m2 for c in contributions), np.zeros((3, 3)))
    cap = float(np.trace(P @ S @ P))
    rows = []
    if d > 0.0:
        g = P @ np.asarray(delta_part_m, float) / d
        for c in contributions:
            rows.append(_row(c, float(g @ c.cov_center_m2 @ g)))
        first = float(g @ S @ g)
        H = (P - np.outer(g, g)) / d
        second = 0.5 * float(np.trace(H @ S @ H @ S))
        var_pos = min(first + second, max(cap, first))
        extra = var_pos - first
    else:  # no direction: the whole in-plane scatter
        for c in contributions:
            rows.append(_row(c, float(np.trace(P @ c.cov_center_m2 @ P))))
        var_pos, extra = cap, 0.0
    rows.append(Component("nonlinearity", float(np.sqrt(max(extra, 0.0))), 0.0,
                          "second-order term of the distance (GUM 5.1.2), bounded by the "
                          "in-plane scatter"))  # fmt: skip
    var_dia = sum(c.var_diameter_m2 for c in contributions)
    return HoleBudget(tuple(rows), float(np.sqrt(var_pos)), float(np.sqrt(var_dia)), k, notes)


def _row(c: Contribution, var_pos: float) -> Component:
    return Component(c.name, float(np.sqrt(max(var_pos, 0.0))),
                     float(np.sqrt(max(c.var_diameter_m2, 0.0))), c.note)  # fmt: skip
