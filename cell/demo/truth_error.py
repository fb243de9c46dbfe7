"""The demo's figures against the simulation's truth.

:func:`truth_error`: measured minus true hole centres in the FIXTURE frame (the cell file's
``part.base``), with the coverage of each hole's stated U; a misplaced part, a misplaced robot
base, shows in it in full (no calibration of the arm sees the part on its fixture).

:func:`datum_truth_error`: the same in the part's DATUM frame (the drawing's A|B|C, the frame
the report's GD&T characteristics use): the measured centres in the DRF the run measured
(report.json ``placement``) against the true centres in the true part's DRF
(:func:`cell.gdt.truth_check.true_evaluation`), in each hole's plane; and the coverage of the
report's characteristics (position by its Monte Carlo U, size by the budget's).
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from cell.records.hole_result import HoleResult, deviations
from cell.sim.world import SimWorld
from robots.transforms import invert


@dataclass
class TruthError:
    """Measured minus true hole centres (m, part frame, at 20 degC) over the measured holes;
    ``coverage``: the fraction of measured characteristics (position deviation and diameter of
    each hole) whose true value lies within the stated expanded uncertainty (NaN: none)."""

    rms_m: float
    max_m: float
    rms_uncompensated_m: float
    diameter_rms_m: float
    n: int
    coverage: float = float("nan")
    n_covered: int = 0
    n_characteristics: int = 0
    position_covered: list[bool] = field(default_factory=list)
    diameter_covered: list[bool] = field(default_factory=list)
    rms_in_plane_m: float = float("nan")
    max_in_plane_m: float = float("nan")


def truth_error(world: SimWorld, results: list[HoleResult]) -> TruthError:
    """Measurement error against the simulation's true holes (their 20 degC geometry), and the
    coverage of the stated uncertainties: ``|d - d_true| <= U_position`` for the position
    deviation (in the plane of the nominal axis) and ``|D - D_true| <= U_diameter``."""
    T_part_cell = invert(world.T_cell_part)  # the true part frame: the part as it lies
    normals = {h.id: np.asarray(h.normal, float) for h in world.cell.part.holes}
    e, e_u, e_d, e_p, cov_p, cov_d = [], [], [], [], [], []
    for r in results:
        if r.center_part_m is None:
            continue
        h = world.holes[r.hole_id]
        true_c = T_part_cell[:3, :3] @ h.position_m + T_part_cell[:3, 3]
        e.append(np.linalg.norm(np.array(r.center_part_m) - true_c))
        e_u.append(np.linalg.norm(np.array(r.extra["center_part_uncompensated_m"]) - true_c))
        e_d.append(r.diameter_m - h.diameter_m)
        n = normals[r.hole_id]
        err = np.array(r.center_part_m) - true_c
        e_p.append(np.linalg.norm(err - (err @ n) * n))
        if r.U_position_m is not None:
            nom = np.array(r.nominal_part_m)
            d_true = deviations(true_c, h.diameter_m, nom, r.nominal_diameter_m, None,
                                normals[r.hole_id])[0]  # fmt: skip
            cov_p.append(bool(abs(r.position_deviation_m - d_true) <= r.U_position_m))
            cov_d.append(bool(abs(r.diameter_m - h.diameter_m) <= r.U_diameter_m))

    def rms(v: list[float]) -> float:
        return float(np.sqrt(np.mean(np.square(v)))) if v else float("nan")

    covered = cov_p + cov_d
    cov = float(np.mean(covered)) if covered else float("nan")
    return TruthError(rms(e), float(max(e, default=float("nan"))), rms(e_u), rms(e_d), len(e),
                      cov, int(np.sum(covered)), len(covered), cov_p, cov_d, rms(e_p),
                      float(max(e_p, default=float("nan"))))  # fmt: skip


@dataclass
class DatumError:
    """Measured minus true hole centres in the datum frame, in each hole's plane (m), over the
    measured holes; coverage of the report's GD&T characteristics (NaN: none)."""

    rms_in_plane_m: float
    max_in_plane_m: float
    n: int
    alignment: str
    position_covered: list[bool] = field(default_factory=list)
    diameter_covered: list[bool] = field(default_factory=list)
    #: after a least-squares rigid fit of all measured centres onto the true ones (no datum
    #: feature's error carried over a lever): the measurement's own error, hole by hole
    best_fit_rms_in_plane_m: float = float("nan")
    best_fit_max_in_plane_m: float = float("nan")

    @property
    def coverage(self) -> float:
        c = self.position_covered + self.diameter_covered
        return float(np.mean(c)) if c else float("nan")


def _T(pose: dict) -> np.ndarray:
    T = np.eye(4)
    T[:3, :3] = Rotation.from_quat(pose["quat_xyzw"]).as_matrix()
    T[:3, 3] = pose["xyz"]
    return T


def datum_truth_error(world: SimWorld, results: list[HoleResult], run_dir: Path) -> DatumError:
    """The demo's figures in the datum frame (module docstring); NaN figures when the run's
    report has no evaluated placement (a cell without datums, too few holes)."""
    from cell.gdt.truth_check import coverage, true_evaluation

    cell = world.cell
    T_part_cell = invert(cell.T_cell_part())  # the nominal part frame: the fixture's
    centres = {k: T_part_cell[:3, :3] @ h.position_m + T_part_cell[:3, 3]
               for k, h in world.holes.items()}  # fmt: skip
    truth = true_evaluation(cell, centres, {k: h.diameter_m for k, h in world.holes.items()})
    doc = json.loads((Path(run_dir) / "report.json").read_text())
    cov = coverage(doc.get("characteristics", []), truth)
    placed = doc.get("placement") or {}
    nan = float("nan")
    if placed.get("T_fixture_part") is None or truth.placement is None:
        return DatumError(nan, nan, 0, doc.get("alignment", ""), cov.of_kind("position"),
                          cov.of_kind("diameter"))  # fmt: skip
    T_meas = invert(_T(placed["T_fixture_part"]))  # fixture -> part (measured DRF)
    T_true = invert(_T(truth.placement["T_fixture_part"]))  # fixture -> part (true DRF)
    normals = {h.id: np.asarray(h.normal, float) / np.linalg.norm(h.normal)
               for h in cell.part.holes}  # fmt: skip
    measured = [r for r in results if r.center_part_m is not None]
    M = np.array([r.center_part_m for r in measured], float).reshape(-1, 3)
    Tc = np.array([centres[r.hole_id] for r in measured], float).reshape(-1, 3)
    N = np.array([normals[r.hole_id] for r in measured], float).reshape(-1, 3)
    e = _in_plane(M @ T_meas[:3, :3].T + T_meas[:3, 3] - (Tc @ T_true[:3, :3].T + T_true[:3, 3]), N)
    bf = _in_plane(_best_fit(M, Tc) - Tc, N) if len(M) >= 3 else np.array([])
    return DatumError(_rms(e), _max(e), len(e), doc.get("alignment", ""),
                      cov.of_kind("position"), cov.of_kind("diameter"), _rms(bf),
                      _max(bf))  # fmt: skip


def _max(v: np.ndarray) -> float:
    return float(v.max()) if len(v) else float("nan")


def _rms(v: np.ndarray) -> float:
    return float(np.sqrt(np.mean(np.square(v)))) if len(v) else float("nan")


def _in_plane(err: np.ndarray, normals: np.ndarray) -> np.ndarray:
    """``|err - (err . n) n|`` per row (m)."""
    return np.linalg.norm(err - np.sum(err * normals, axis=1)[:, None] * normals, axis=1)


def _best_fit(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``a`` (N, 3) moved by the least-squares rigid motion onto ``b`` (Kabsch, SciPy)."""
    ca, cb = a.mean(axis=0), b.mean(axis=0)
    R, _ = Rotation.align_vectors(b - cb, a - ca)
    return R.apply(a - ca) + cb
