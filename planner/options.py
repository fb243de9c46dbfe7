"""Settings of the tour planner (frozen dataclass, documented defaults)."""

from __future__ import annotations

import math
import numbers
from dataclasses import asdict, dataclass, fields
from typing import Any

from planner.errors import OptionsError

#: the largest seed: OMPL's generator takes seed + 1 as an unsigned 32-bit number (signed, to
#: be safe with every binding)
MAX_SEED = 2**31 - 2


@dataclass(frozen=True)
class Options:
    """Settings of :func:`planner.plan_tour`.

    Viewpoints:
        roll_step_deg: sampling step of the roll about the view axis (deg).
        tilt_deg: half-angle of the tilt cone around the hole axis (deg); 0 = view along the axis.
        tilt_azimuths: directions sampled on the cone when ``tilt_deg > 0``.
        fallback_tilt_deg: a hole with no collision-free view along its axis is tried again
            with a tilt cone of this half-angle (deg; 0 = never); a view a few degrees off
            the axis is what an operator does where the arm's wrist would touch the head.
        strict: raise :class:`~planner.errors.UnreachableHoleError` instead of leaving holes out.
    Sequencing:
        seed: seed of every random choice (sequencer and OMPL); the same seed gives the same tour.
        time_budget_s: hard cap on the sequencer's search (s); ``None``: 1 s + 0.015 s per hole.
        effort: work of the search relative to the default (iterations and patience scale with it).
        nodes_per_hole: candidate configurations per hole the search starts with (up to 120
            holes the task-space tour's and the found order's best configurations among
            every candidate join them: :mod:`planner.full_choice`).
        sequencer: ``"lns"`` (large-neighbourhood search, default), ``"pyvrp"`` (PyVRP,
            one optional client per candidate, one required group per hole) or ``"ortools"``
            (OR-Tools routing with one disjunction per hole).
        roadmap_neighbours: before the first solve, check the straight motions from every
            candidate node to this many nearest nodes of other holes in one batch; colliding
            ones cost their shortest detour through the free ones (:mod:`planner.roadmap`).
            0 turns the roadmap off (only the lazy checks of the tour's edges remain).
    Paths:
        joint_step_deg: collision checks along a motion at least every this joint change (deg).
        tcp_step_m: ... and at least every this TCP displacement (m).
        segment_time_s: OMPL time budget per segment (s); an unsolved segment is an error.
        refine_rounds: times the measured duration of segments that needed a detour is fed
            back to the sequencer, which then re-sequences from the current tour.
    Timing:
        pass_through_waypoints: fly through the waypoints of an OMPL path where the sampled
            motion stays collision-free (else every waypoint is a stop).
        dt: controller period at which the trajectory is sampled (s).
        dwell_s: rest at each stop for settling and capture (s).
    """

    roll_step_deg: float = 15.0
    tilt_deg: float = 0.0
    tilt_azimuths: int = 6
    fallback_tilt_deg: float = 10.0
    strict: bool = False
    seed: int = 0
    time_budget_s: float | None = None
    effort: float = 1.0
    nodes_per_hole: int = 16
    sequencer: str = "lns"
    roadmap_neighbours: int = 8
    joint_step_deg: float = 0.5
    tcp_step_m: float = 0.002
    segment_time_s: float = 2.0
    refine_rounds: int = 3
    pass_through_waypoints: bool = True
    dt: float = 0.004
    dwell_s: float = 0.2

    def __post_init__(self) -> None:
        positive = (
            "roll_step_deg",
            "effort",
            "joint_step_deg",
            "tcp_step_m",
            "segment_time_s",
            "dt",
        )
        for name in positive:
            value = getattr(self, name)
            if not (isinstance(value, int | float) and math.isfinite(value) and value > 0):
                raise OptionsError(name, value, "must be a positive number")
        if not isinstance(self.seed, numbers.Integral) or not 0 <= self.seed <= MAX_SEED:
            raise OptionsError("seed", self.seed, f"must be an integer in [0, {MAX_SEED}]")
        if not 0 < self.roll_step_deg <= 360:
            raise OptionsError("roll_step_deg", self.roll_step_deg, "must lie in (0, 360]")
        if not 0 <= self.tilt_deg < 90:
            raise OptionsError("tilt_deg", self.tilt_deg, "must lie in [0, 90)")
        if not 0 <= self.fallback_tilt_deg < 90:
            raise OptionsError("fallback_tilt_deg", self.fallback_tilt_deg, "must lie in [0, 90)")
        if self.tilt_azimuths < 1:
            raise OptionsError("tilt_azimuths", self.tilt_azimuths, "must be at least 1")
        if self.refine_rounds < 0:
            raise OptionsError("refine_rounds", self.refine_rounds, "must be zero or positive")
        if self.nodes_per_hole < 1:
            raise OptionsError("nodes_per_hole", self.nodes_per_hole, "must be at least 1")
        if self.sequencer not in ("lns", "pyvrp", "ortools"):
            raise OptionsError("sequencer", self.sequencer, "must be 'lns', 'pyvrp' or 'ortools'")
        if not isinstance(self.roadmap_neighbours, int) or self.roadmap_neighbours < 0:
            raise OptionsError(
                "roadmap_neighbours", self.roadmap_neighbours, "must be zero or a positive integer"
            )
        if self.dwell_s < 0 or not math.isfinite(self.dwell_s):
            raise OptionsError("dwell_s", self.dwell_s, "must be zero or positive")
        if self.time_budget_s is not None and not self.time_budget_s > 0:
            raise OptionsError("time_budget_s", self.time_budget_s, "must be positive (or None)")

    def budget_s(self, n_holes: int) -> float:
        """The sequencer's time cap (s) for ``n_holes`` holes."""
        if self.time_budget_s is not None:
            return float(self.time_budget_s)
        return 1.0 + 0.015 * n_holes

    def to_dict(self) -> dict[str, Any]:
        """Plain mapping of every setting (stored in ``tour.json``)."""
        return asdict(self)

    @classmethod
    def field_names(cls) -> list[str]:
        """Names of every setting."""
        return [f.name for f in fields(cls)]
