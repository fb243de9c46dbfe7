"""The characteristics of the simulated part as it truly is, and how often the reported ones
cover them: ``|value - true value| <= U`` (position by its Monte Carlo U, size by the
budget's).

The true values come from the same evaluation (:func:`cell.gdt.evaluate.evaluate`) run on
the simulator's true holes (their 20 degC geometry in the nominal part frame, wherever the
part sits on its fixture) without uncertainty: the true DRF from the true datum features, the
true deviations in it.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation

from cell.config import CellConfig
from cell.gdt.evaluate import Evaluation, evaluate
from cell.gdt.montecarlo import McOptions
from cell.records.hole_result import HoleResult


@dataclass
class Coverage:
    """Per characteristic id: (reported value, U, true value); the covered fraction."""

    rows: dict[str, tuple[float, float, float]] = field(default_factory=dict)

    @property
    def covered(self) -> list[bool]:
        return [abs(v - t) <= U for v, U, t in self.rows.values()]

    @property
    def fraction(self) -> float:
        """Covered fraction (NaN: no characteristic)."""
        return float(np.mean(self.covered)) if self.rows else float("nan")

    def of_kind(self, kind: str) -> list[bool]:
        """Covered flags of the characteristics of one kind (``position``, ``diameter``)."""
        return [abs(v - t) <= U for k, (v, U, t) in self.rows.items() if k.endswith(kind)]


def true_results(cell: CellConfig, true_centres_part_m: dict[str, np.ndarray],
                 true_diameters_m: dict[str, float]) -> list[HoleResult]:  # fmt: skip
    """Exact 'measurements' of the true holes (no uncertainty), for :func:`evaluate`."""
    out = []
    for i, h in enumerate(cell.part.holes):
        if h.id not in true_centres_part_m:
            continue
        out.append(HoleResult(
            hole_id=h.id, stop_index=i, status="ok", nominal_part_m=tuple(h.position),
            nominal_diameter_m=h.diameter, tolerance_m=h.tolerance,
            center_part_m=tuple(float(v) for v in true_centres_part_m[h.id]),
            normal_part=tuple(h.normal), diameter_m=float(true_diameters_m[h.id]),
            rms_m=0.0, U_diameter_m=0.0,
            extra={"cov_center_part_m2": np.zeros((3, 3)).tolist()}))  # fmt: skip
    return out


def true_evaluation(cell: CellConfig, true_centres_part_m: dict[str, np.ndarray],
                    true_diameters_m: dict[str, float]) -> Evaluation:  # fmt: skip
    """The evaluation of the true part: its true characteristics and its true placement (the
    true DRF's, which differs from the simulator's ``part_placement_error`` by what the datum
    features' own machining scatter does to the DRF)."""
    results = true_results(cell, true_centres_part_m, true_diameters_m)
    return evaluate(cell, results, McOptions(n_draws=2))


def coverage(reported: list[dict[str, Any]], truth: Evaluation) -> Coverage:
    """Compare report.json's ``characteristics`` with the true part's (``truth``)."""
    true_by_id = {c["id"]: c for c in truth.characteristics}
    out = Coverage()
    for c in reported:
        t = true_by_id.get(c["id"])
        if c["value_m"] is None or t is None or t["value_m"] is None:
            continue
        out.rows[c["id"]] = (float(c["value_m"]), float(c["U_m"]), float(t["value_m"]))
    return out


def placement_error(reported: dict[str, Any], truth: Evaluation) -> dict[str, Any]:
    """The reported placement minus the true one: translation (m) and rotation vector (rad)
    per axis, and whether each lies within the reported U."""
    true_T = truth.placement["T_fixture_part"]
    T = reported["T_fixture_part"]
    dt = np.subtract(T["xyz"], true_T["xyz"])
    R = Rotation.from_quat(T["quat_xyzw"]) * Rotation.from_quat(true_T["quat_xyzw"]).inv()
    dr = R.as_rotvec()
    within = bool(np.all(np.abs(dt) <= reported["U_xyz_m"])
                  and np.all(np.abs(dr) <= reported["U_rotation_rad"]))  # fmt: skip
    return {"xyz_m": dt.tolist(), "rotation_rad": dr.tolist(), "within_U": within}
