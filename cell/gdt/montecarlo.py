"""Monte Carlo propagation (GUM Supplement 1, JCGM 101:2008) of the measured centres through
the alignment into the characteristics.

Each measured hole's centre is drawn from a normal distribution about its measured value
with the covariances of its budget's components (part frame, m^2; the run stores them with
each hole, :func:`gdt_extra`). The components are drawn as they act in a run:

- ``circle_fit``, ``robot_repeatability`` and ``thermal_model``: independently per hole (the
  thermal model's error varies with the pose; taken as independent, which overstates what a
  common part of it does to an alignment);
- ``resection`` (a referenced stop): independently per hole (each stop's own image noise);
- ``survey_markers`` (a referenced stop): one error of the whole marker network for the run,
  ``z ~ N(0, I_3N)``, mapped into each hole's centre through the factor the run stored with it
  (``survey_markers_factor_part``, 3 x 3N: the hole's sensitivity to the markers through its
  stop's resection times a square root of the network's covariance). Stops that share markers
  then share their error, as they do: drawn independently, the datum features' marker errors
  would turn the datum frame and swing the far holes by their levers (five to ten times the
  real scatter on the built-in frame). Without the factor: independently per hole;
- ``stereo_calibration``: one error of the head for the whole run (the head is off its
  calibration by the same amount at every stop): one standard normal draw per run, mapped into
  each hole's centre through its own covariance in the left camera frame and that stop's
  ``R_part_left``;
- ``part_temperature``: one scale error for the whole part (its expansion about the part
  origin): one draw per run along each hole's own direction;
- ``cell_calibration`` (a run with ``--calibration``): one error of the calibration's
  parameters for the whole run, ``z ~ N(0, I_p)``, mapped into each hole's centre through the
  factor the run stored with it (``cell_calibration_factor_part``, 3 x p: the hole's
  sensitivity to the parameters times a square root of their covariance), so the part of it
  that moves every hole together (a rigid motion) cancels in a datum frame.

A result stored before the components were kept has only its total (or only the projected
``u_position_m``, taken as an isotropic standard deviation per axis) and is drawn
independently.

The coverage interval of a value ``y`` estimated as ``y0`` is ``[y0 - U, y0 + U]`` with ``U``
the ``p`` quantile of ``|y_r - y0|`` over the draws ``y_r`` (the shortest interval symmetric
about the estimate that holds ``p`` of the draws). For a position near zero (a distance,
not Gaussian: its draws pile up against zero) this interval still reaches down to the true
value, where the central interval of the draws would not.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from cell.records.hole_result import HoleResult


@dataclass(frozen=True)
class McOptions:
    """Settings of the Monte Carlo evaluation.

    Attributes:
        n_draws: draws of every measured centre (GUM S1: 10^4 for two significant digits of
            a 95 % interval; 2000 keep U within about 3 % at a tenth of the time).
        n_draws_minimax: draws for a minimax best fit (one optimisation per draw).
        coverage: coverage probability of the expanded uncertainties.
        seed: seed of the draws (a report is reproducible).
    """

    n_draws: int = 2000
    n_draws_minimax: int = 200
    coverage: float = 0.95
    seed: int = 19


INDEPENDENT = ("circle_fit", "robot_repeatability", "thermal_model", "resection", "survey_markers")


def gdt_extra(contributions: list[Any], T_part_left: np.ndarray) -> dict[str, Any]:
    """What a run stores with each hole for the draws: the total and per-component centre
    covariances (part frame, m^2) and the stop's ``R_part_left``."""
    total = sum((c.cov_center_m2 for c in contributions), np.zeros((3, 3)))
    return {"cov_center_part_m2": total.tolist(),
            "cov_components_part_m2": {c.name: np.asarray(c.cov_center_m2).tolist()
                                       for c in contributions},
            "R_part_left": np.asarray(T_part_left)[:3, :3].tolist()}  # fmt: skip


def centre_cov(r: HoleResult) -> np.ndarray:
    """The total covariance of a measured centre (3x3, part frame, m^2), see the module doc."""
    cov = r.extra.get("cov_center_part_m2")
    if cov is not None:
        return np.asarray(cov, float)
    u = (r.budget or {}).get("u_position_m") or r.u_center_m or 0.0
    return np.eye(3) * float(u) ** 2


def _chol(S: np.ndarray) -> np.ndarray:
    w, v = np.linalg.eigh(0.5 * (S + S.T))
    return v * np.sqrt(np.clip(w, 0.0, None))


def _error_draws(r: HoleResult, z_cal: np.ndarray, z_temp: np.ndarray, rng: np.random.Generator,
                 z_cell: _SharedDraws | None = None,
                 z_net: _SharedDraws | None = None) -> np.ndarray:  # fmt: skip
    """Draws ``(n, 3)`` of a centre's error (m), see the module doc."""
    n = len(z_temp)
    parts = r.extra.get("cov_components_part_m2")
    if parts is None or "R_part_left" not in r.extra:
        return rng.standard_normal((n, 3)) @ _chol(centre_cov(r)).T
    shared = r.extra.get("survey_markers_factor_part") if z_net is not None else None
    indep_keys = [k for k in INDEPENDENT if k in parts
                  and not (k == "survey_markers" and shared is not None)]  # fmt: skip
    indep = sum((np.asarray(parts[k], float) for k in indep_keys), np.zeros((3, 3)))
    err = rng.standard_normal((n, 3)) @ _chol(indep).T
    if "stereo_calibration" in parts:
        R = np.asarray(r.extra["R_part_left"], float)
        L_left = _chol(R.T @ np.asarray(parts["stereo_calibration"], float) @ R)
        err += z_cal @ (R @ L_left).T
    if "part_temperature" in parts:
        w, v = np.linalg.eigh(np.asarray(parts["part_temperature"], float))
        vec = v[:, -1] * np.sqrt(max(w[-1], 0.0))
        vec = vec if vec @ np.asarray(r.center_part_m) >= 0 else -vec
        err += z_temp[:, None] * vec
    A = r.extra.get("cell_calibration_factor_part")
    if A is not None and "cell_calibration" in parts and z_cell is not None:
        A = np.asarray(A, float)
        err += z_cell.get(A.shape[1]) @ A.T
    if shared is not None:
        F = np.asarray(shared, float)
        err += z_net.get(F.shape[1]) @ F.T
    return err


class _SharedDraws:
    """Standard normal draws ``(n, p)`` shared by every hole of a run (one per dimension
    ``p``), from their own stream so runs without them draw as before."""

    def __init__(self, n: int, seed: int, stream: int = 18) -> None:
        self.n, self.seed, self.stream = n, seed, stream
        self._z: dict[int, np.ndarray] = {}

    def get(self, p: int) -> np.ndarray:
        if p not in self._z:
            rng = np.random.default_rng([self.seed, self.stream, p])
            self._z[p] = rng.standard_normal((self.n, p))
        return self._z[p]


def draw_centres(results: list[HoleResult], n: int, seed: int) -> dict[str, np.ndarray]:
    """``n`` draws ``(n, 3)`` of every measured centre (part frame, m), keyed by hole id; the
    first draw of each is the measured value itself (the estimate)."""
    rng = np.random.default_rng(seed)
    z_cal, z_temp = rng.standard_normal((n, 3)), rng.standard_normal(n)
    z_cell, z_net = _SharedDraws(n, seed), _SharedDraws(n, seed, 25)
    out = {}
    for r in results:
        if not r.measured:
            continue
        c = np.asarray(r.center_part_m, float)
        d = c + _error_draws(r, z_cal, z_temp, rng, z_cell, z_net)
        d[0] = c
        out[r.hole_id] = d
    return out


def expanded(draws: np.ndarray, estimate: float, p: float) -> float:
    """``U``: the ``p`` quantile of ``|draws - estimate|`` (m), see the module doc."""
    return float(np.quantile(np.abs(np.asarray(draws, float) - estimate), p))
