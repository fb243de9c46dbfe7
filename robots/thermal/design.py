"""The reference plan designed for a tour: optimal experimental design of the reference views.

What matters is the model's error at the tour's stops, not at the reference targets. For the
length terms (link ``i``'s lengths scale by ``1 + k_i * dT_i``) the measured target position in
the TCP frame moves by ``G_v @ (k * dT)`` at view ``v`` and a stop's TCP (and every point fixed
to it: rotations do not depend on lengths) by ``H_s @ (k * dT)``, with

    G_v = -R_base_tcp(q_v)^T @ dt_tcp/du (q_v),   H_s = R_cell_base @ dt_tcp/du (q_s),

``du_i = k_i * dT_i`` (m per unit scale, central differences on the D-H table; exact, since the
position is linear in the lengths). The identification (:mod:`robots.thermal.identify`) removes
each view's mean and fits ``k`` by least squares, so with every link warming along the same
anticipated curve ``dT(t)`` over the rounds, the terms' covariance is

    Sigma(V) = sigma^2 / s_T * (sum_{v in V} G_v^T G_v)^-1,   s_T = sum_t (dT(t) - mean dT)^2,

and the predicted error at stop ``s`` at rise ``dT_eval`` has covariance
``dT_eval^2 H_s Sigma H_s^T``. The design minimises the sum over the stops of its trace (an
I-optimal design, weighted by ``W = sum_s H_s^T H_s``): ``phi(V) = trace(W M(V)^-1)``.
Candidates are every reachable, collision-free arm configuration (one per IK arm branch, the
roll nearest the rest pose: a roll about the view axis does not change a length term's
information) of every view direction (tilts and azimuths from the target normal) of every
target; the views are chosen greedily, then improved by exchange (Fedorov) until no single swap
lowers ``phi``. A small ridge (``ridge``, relative) makes the early, still singular, greedy
steps comparable; the reported figures are without it. Noise, schedule and rise only scale
``phi``, so the choice does not depend on them.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robots.design import choose_by_information
from robots.dh import DHTable, fk_dh_arrays
from robots.ik import solve_ik
from robots.thermal.errors import ThermalDataError, ThermalSpecError
from robots.thermal.model import LENGTH_TERMS
from robots.thermal.plan import view_pose
from robots.transforms import invert

Array = NDArray[np.float64]

#: exchange passes of the design (each tries every slot; it stops when none improves)
EXCHANGE_PASSES = 50


@dataclass(frozen=True)
class DesignOptions:
    """Settings of :func:`design_views`.

    Attributes:
        n_views: views to choose (None: three per target, the old plan's count).
        tilts_rad: tilts of the view axis from the target normal considered (rad); the stereo
            head must still see the target's circle.
        n_azimuths: azimuths per non-zero tilt, evenly spaced.
        roll_step_rad: roll sampling about the view axis (rad), for reach and collision.
        noise_m: stereo measurement noise per axis (m).
        rise_K: anticipated warm-up: every link rises ``rise_K * (1 - exp(-t / tau_s))``.
        tau_s: its time constant (s).
        duration_s: length of the reference warm-up (s); the stops are predicted at its end.
        every_s: period of the reference rounds (s).
        ridge: ridge used only while choosing, relative to the mean candidate's information
            (makes the first, still singular, greedy steps comparable; independent of the
            noise and schedule, so the choice is too).
    """

    n_views: int | None = None
    tilts_rad: tuple[float, ...] = (0.0, 0.25, 0.5)
    n_azimuths: int = 8
    roll_step_rad: float = np.pi / 6
    noise_m: float = 5e-6
    rise_K: float = 15.0  # noqa: N815 (unit suffix)
    tau_s: float = 2400.0
    duration_s: float = 7200.0
    every_s: float = 300.0
    ridge: float = 1e-5

    def __post_init__(self) -> None:
        checks = {
            "n_views": self.n_views is None or self.n_views >= 1,
            "tilts_rad": bool(self.tilts_rad) and all(0.0 <= t < np.pi / 2 for t in self.tilts_rad),
            "n_azimuths": self.n_azimuths >= 1,
            "roll_step_rad": 0 < self.roll_step_rad <= 2 * np.pi,
            "noise_m": self.noise_m > 0,
            "rise_K": self.rise_K > 0,
            "tau_s": self.tau_s > 0,
            "duration_s": self.duration_s > 0,
            "every_s": 0 < self.every_s <= self.duration_s,
            "ridge": 0 < self.ridge < 1,
        }
        for name, ok in checks.items():
            if not ok:
                raise ThermalSpecError(name, getattr(self, name), "out of range")

    def temperature_weights(self) -> tuple[float, float]:
        """``(s_T K^2, dT_eval K)``: the spread of the anticipated rises over the rounds (each
        view's mean removed) and the rise at the end of the warm-up."""
        t = np.arange(0.0, self.duration_s + 1e-9, self.every_s)
        dT = self.rise_K * (1.0 - np.exp(-t / self.tau_s))
        return float(np.sum((dT - dT.mean()) ** 2)), float(dT[-1])


@dataclass(frozen=True)
class Candidate:
    """One reachable, collision-free view: target, joints (rad), and the view's geometry."""

    target_id: str
    q_rad: Array
    tilt_rad: float
    azimuth_rad: float
    roll_rad: float


@dataclass(frozen=True)
class Design:
    """The chosen views and what they predict.

    Attributes:
        views: the chosen candidates, in the order chosen.
        terms: the length terms the design is for (links with a D-H length).
        stop_sigma_m: predicted 1-sigma 3D error (root of the covariance trace) per stop (m),
            at the end of the anticipated warm-up; inf when the views cannot identify the terms.
        covariance: predicted covariance of the terms (1/K squared), terms order.
        n_candidates: candidates considered.
        skipped: per target id, why it has no candidate (unreachable, every view in collision).
    """

    views: list[Candidate]
    terms: tuple[str, ...]
    stop_sigma_m: Array
    covariance: Array
    n_candidates: int
    skipped: dict[str, str] = field(default_factory=dict)

    @property
    def predicted_rms_m(self) -> float:
        """Predicted RMS error over the stops (m)."""
        return float(np.sqrt(np.mean(self.stop_sigma_m**2)))

    @property
    def poses(self) -> list[tuple[str, Array]]:
        """``(target id, joints)`` per view, the plan format of the identification."""
        return [(c.target_id, c.q_rad) for c in self.views]


def length_links(table: DHTable) -> list[int]:
    """Links (0-based) with a D-H length: the length terms that can have an effect."""
    a, d, _, _ = table.arrays()
    return [i for i in range(6) if a[i] != 0.0 or d[i] != 0.0]


def tcp_sensitivity(table: DHTable, T_tool0_tcp: ArrayLike, q: ArrayLike) -> tuple[Array, Array]:
    """``(R_base_tcp (N, 3, 3), dt_tcp/du (N, 3, n_links))`` at joints ``q`` (N, 6): the TCP
    position's change (base frame, m) per unit relative lengthening of each link with a length."""
    q = np.atleast_2d(np.asarray(q, float))
    a0, d0, alpha, off = table.arrays()
    T_tt = np.asarray(T_tool0_tcp, float)
    links, h = length_links(table), 1e-3
    cols = []
    for i in links:
        pts = []
        for sign in (1.0, -1.0):
            s = np.ones(6)
            s[i] += sign * h
            pts.append((fk_dh_arrays(a0 * s, d0 * s, alpha, off, q) @ T_tt)[..., :3, 3])
        cols.append((pts[0] - pts[1]) / (2 * h))
    R = (fk_dh_arrays(a0, d0, alpha, off, q) @ T_tt)[..., :3, :3]
    return R, np.stack(cols, axis=-1)


def candidate_views(
    table: DHTable,
    lower: ArrayLike,
    upper: ArrayLike,
    T_cell_base: ArrayLike,
    T_tool0_tcp: ArrayLike,
    targets: Mapping[str, tuple[ArrayLike, ArrayLike]],
    standoff_m: float,
    options: DesignOptions | None = None,
    accept: Callable[[Array], bool] | None = None,
    rest_q: ArrayLike | None = None,
) -> tuple[list[Candidate], dict[str, str]]:
    """Every candidate view of every target (cell-frame ``(position m, unit normal)`` by id):
    one per (view direction, IK arm branch), the roll whose solution is nearest ``rest_q``
    among those ``accept(q)`` passes (e.g. not in collision). Returns the candidates and, per
    target without any, the reason."""
    o = options or DesignOptions()
    T_base_cell = invert(np.asarray(T_cell_base, float))
    T_tcp_tool0 = invert(np.asarray(T_tool0_tcp, float))
    lo, hi = np.asarray(lower, float), np.asarray(upper, float)
    rolls = np.arange(0.0, 2 * np.pi - 1e-9, o.roll_step_rad)
    directions = [(t, az) for t in o.tilts_rad for az in (
        [0.0] if t == 0.0 else 2 * np.pi * np.arange(o.n_azimuths) / o.n_azimuths)]  # fmt: skip
    out: list[Candidate] = []
    skipped: dict[str, str] = {}
    for tid, (pos, normal) in targets.items():
        p = T_base_cell[:3, :3] @ np.asarray(pos, float) + T_base_cell[:3, 3]
        n = T_base_cell[:3, :3] @ np.asarray(normal, float)
        rest = (np.array([np.arctan2(p[1], p[0]), 0.3, 0.0, 0.0, 1.0, 0.0])
                if rest_q is None else np.asarray(rest_q, float))  # fmt: skip
        before, reasons = len(out), set()
        for tilt, az in directions:
            by_branch: dict[tuple[float, ...], list[tuple[float, float, Array]]] = {}
            for roll in rolls:
                T = view_pose(p, n, tilt, az, roll, standoff_m) @ T_tcp_tool0
                ik = solve_ik(table, T, lo, hi)
                if not ik.ok:
                    reasons.add(ik.reason or "no IK solution")
                for q in ik.solutions:
                    key = tuple(np.round(q[:3], 3))
                    by_branch.setdefault(key, []).append((float(np.abs(q - rest).sum()), roll, q))
            for sols in by_branch.values():
                for _, roll, q in sorted(sols, key=lambda s: s[0]):
                    if accept is None or accept(q):
                        out.append(Candidate(tid, q, float(tilt), float(az), float(roll)))
                        break
                else:
                    reasons.add("in collision")
        if len(out) == before:
            skipped[tid] = ", ".join(sorted(reasons)) or "no view"
    return out, skipped


def evaluate(
    table: DHTable,
    T_cell_base: ArrayLike,
    T_tool0_tcp: ArrayLike,
    views_q: ArrayLike,
    stops_q: ArrayLike,
    options: DesignOptions | None = None,
) -> tuple[Array, Array]:
    """``(stop_sigma_m (S,), covariance (n, n) 1/K^2)`` predicted for the views ``views_q``
    (V, 6) at the stops ``stops_q`` (S, 6): see the module docstring. inf / inf when the
    views leave a term undetermined."""
    o = options or DesignOptions()
    s_T, dT_eval = o.temperature_weights()
    _, D_v = tcp_sensitivity(table, T_tool0_tcp, views_q)
    _, D_s = tcp_sensitivity(table, T_tool0_tcp, stops_q)
    M = np.einsum("vki,vkj->ij", D_v, D_v) * s_T / o.noise_m**2
    n = M.shape[0]
    s = np.linalg.svd(M, compute_uv=False)
    if s[-1] <= s[0] * 1e-12:
        return np.full(len(D_s), np.inf), np.full((n, n), np.inf)
    cov = np.linalg.inv(M)
    R_cb = np.asarray(T_cell_base, float)[:3, :3]
    H = np.einsum("ab,sbi->sai", R_cb, D_s)
    C = dT_eval**2 * np.einsum("sai,ij,saj->s", H, cov, H)
    return np.sqrt(np.maximum(C, 0.0)), cov


def design_views(
    table: DHTable,
    T_cell_base: ArrayLike,
    T_tool0_tcp: ArrayLike,
    candidates: Sequence[Candidate],
    stops_q: ArrayLike,
    options: DesignOptions | None = None,
    n_targets: int | None = None,
    fixed: Sequence[int] = (),
) -> Design:
    """Choose ``options.n_views`` (default three per target) of ``candidates`` minimising the
    predicted error at the stops ``stops_q`` (S, 6) rad. ``fixed``: candidate indices that stay.
    Raises :class:`ThermalDataError` when there is no candidate or no stop."""
    o = options or DesignOptions()
    stops = np.atleast_2d(np.asarray(stops_q, float))
    if not len(candidates):
        raise ThermalDataError("reference plan", "no reachable, collision-free reference view")
    if stops.size == 0:
        raise ThermalDataError("reference plan", "no tour stops to design the reference plan for")
    n_t = n_targets or len({c.target_id for c in candidates})
    n = min(o.n_views or 3 * n_t, len(candidates))
    Q = np.array([c.q_rad for c in candidates])
    _, D_v = tcp_sensitivity(table, T_tool0_tcp, Q)
    _, D_s = tcp_sensitivity(table, T_tool0_tcp, stops)
    blocks = np.einsum("vki,vkj->vij", D_v, D_v)
    W = np.einsum("ski,skj->ij", D_s, D_s)
    n_terms = blocks.shape[1]
    ridge = np.eye(n_terms) * o.ridge * np.trace(blocks.mean(axis=0)) / n_terms
    chosen = choose_by_information(blocks, n, ridge, W, EXCHANGE_PASSES, fixed=list(fixed))
    views = [candidates[i] for i in chosen]
    sigma, cov = evaluate(table, T_cell_base, T_tool0_tcp, Q[chosen], stops, o)
    terms = tuple(LENGTH_TERMS[i] for i in length_links(table))
    return Design(views, terms, sigma, cov, len(candidates))
