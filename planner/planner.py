"""The tour planner: viewpoints → sequence → paths → timing → :class:`~planner.tour.Tour`.

``plan_tour(cell, options)`` takes any object shaped like ``cell.config.CellConfig``
(:class:`planner.protocols.CellLike`); the planner never imports :mod:`cell`.
Library code reports progress through an optional callback
``progress(stage, done, total)`` and logs with :mod:`logging`.
"""

from __future__ import annotations

import hashlib
import itertools
import logging
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from planner.errors import (
    NoReachableHoleError,
    StartConfigurationError,
    TourCellMismatchError,
    UnreachableHoleError,
)
from planner.options import Options
from planner.paths import MotionChecker
from planner.protocols import ArmLike, CellLike
from planner.segments import Segment, SegmentCache
from planner.sequence import GtspSequencer, SequenceResult
from planner.timing import JointLimits, TimedMotion
from planner.tour import LeftOut, Stop, Tour
from planner.trajectory import Dwell, sample_timeline
from planner.viewpoints import HoleCandidates, hole_candidates

log = logging.getLogger(__name__)

ProgressCallback = Callable[[str, int, int], None]
#: a replacement sequencer: (home q, candidates per hole, limits) -> SequenceResult
Sequencer = Callable[[NDArray[np.float64], list[HoleCandidates], JointLimits], SequenceResult]
STAGES = ("viewpoints", "sequence", "paths", "timing")
#: time cap of each repair search after costs changed, as a share of the sequencing budget
REFINE_SHARE = 0.15
#: at most this many lazy re-sequencing rounds ...
LAZY_ROUNDS = 20
#: ... and at most this share of the sequencing budget in time
LAZY_BUDGET_SHARE = 0.5
#: lazy edge checks are this many times coarser than the set motion resolution
LAZY_COARSENESS = 3.0
#: estimated duration of a colliding straight edge until its detour is measured: factor, extra s
DETOUR_FACTOR = 1.5
DETOUR_EXTRA_S = 0.3


def _no_progress(stage: str, done: int, total: int) -> None:
    log.debug("%s %d/%d", stage, done, total)


def cell_sha256(cell: CellLike) -> str:
    """Identity of a cell: SHA-256 of its file text (or of its name and holes if built in code)."""
    text = cell.raw_text
    if not text:
        holes = [
            (h.id, h.position_m.round(9).tolist(), h.normal.round(9).tolist())
            for h in cell.holes_in_cell()
        ]
        text = repr((cell.name, cell.robot.model, cell.home_q().round(9).tolist(), holes))
    return hashlib.sha256(text.encode()).hexdigest()


def check_tour_for_cell(tour: Tour, cell: CellLike) -> None:
    """Raise :class:`TourCellMismatchError` unless ``tour`` was planned for exactly ``cell``.

    Compares the robot model, the cell name and the SHA-256 of the cell file text.
    """
    checks = (
        ("robot model", tour.robot_model, cell.robot.model),
        ("cell name", tour.cell_name, cell.name),
        ("cell sha256", tour.cell_sha256, cell_sha256(cell)),
    )
    for field, in_tour, in_cell in checks:
        if in_tour != in_cell:
            raise TourCellMismatchError(field, in_tour, in_cell)


@dataclass(frozen=True)
class _Route:
    hole_ids: list[str]
    q: NDArray[np.float64]  # (n, dof) stop configurations in order
    branch: list[int]
    candidates: list[HoleCandidates]


class TourPlanner:
    """Plans inspection tours with fixed :class:`Options`; :meth:`plan` does one cell.

    ``sequencer`` replaces the built-in sequencing stage (benchmarks use it to run
    other methods through the same viewpoints, paths and timing); ``sequencer_name``
    is recorded in the tour's settings.
    """

    def __init__(
        self,
        options: Options | None = None,
        progress: ProgressCallback | None = None,
        sequencer: Sequencer | None = None,
        sequencer_name: str = "custom",
    ) -> None:
        self.options = options or Options()
        self.progress = progress or _no_progress
        self.sequencer = sequencer
        self.sequencer_name = sequencer_name if sequencer else self.options.sequencer

    def _home(self, arm: ArmLike, cell: CellLike) -> NDArray[np.float64]:
        home = np.asarray(cell.home_q(), dtype=float)
        if not arm.within_limits(home):
            raise StartConfigurationError(home.round(4).tolist(), "outside the joint limits")
        if arm.in_collision(home):
            pairs = ", ".join(f"{a} with {b}" for a, b in arm.colliding_pairs(home)[:3])
            raise StartConfigurationError(home.round(4).tolist(), f"in collision ({pairs})")
        return home

    def _viewpoints(
        self, arm: ArmLike, cell: CellLike
    ) -> tuple[list[HoleCandidates], list[LeftOut]]:
        o = self.options
        holes = cell.holes_in_cell()
        found, left = [], []
        for i, hole in enumerate(holes):
            c = hole_candidates(
                arm, hole, cell.tool.standoff_m, o.roll_step_deg, o.tilt_deg, o.tilt_azimuths
            )
            if not c.ok and o.fallback_tilt_deg > o.tilt_deg:
                tilted = hole_candidates(
                    arm,
                    hole,
                    cell.tool.standoff_m,
                    o.roll_step_deg,
                    o.fallback_tilt_deg,
                    o.tilt_azimuths,
                )
                if tilted.ok:
                    log.info(
                        "hole %s: viewed up to %g deg off its axis", hole.id, o.fallback_tilt_deg
                    )
                    c = tilted
            if c.ok:
                found.append(c)
            else:
                left.append(LeftOut(hole.id, c.reason or "no viewpoint"))
            self.progress("viewpoints", i + 1, len(holes))
        reasons = {h.hole_id: h.reason for h in left}
        if not found:
            raise NoReachableHoleError(reasons)
        if left and o.strict:
            raise UnreachableHoleError(reasons)
        for h in left:
            log.warning("hole %s left out: %s", h.hole_id, h.reason)
        return found, left

    def _route(self, cands: list[HoleCandidates], res: SequenceResult) -> _Route:
        pairs = list(zip(res.order, res.choice, strict=True))
        return _Route(
            hole_ids=[cands[h].hole_id for h, _ in pairs],
            q=np.array([cands[h].q[c] for h, c in pairs]),
            branch=[int(cands[h].branch[c]) for h, c in pairs],
            candidates=[cands[h] for h, _ in pairs],
        )

    def _segments(
        self, home: NDArray[np.float64], route: _Route, cache: SegmentCache
    ) -> list[Segment]:
        points = [home, *route.q, home]
        names = ["home", *route.hole_ids, "home"]
        out = []
        for k in range(len(points) - 1):
            out.append(cache.get(points[k], points[k + 1], (names[k], names[k + 1])))
            self.progress("paths", k + 1, len(points) - 1)
        return out

    def _avoid_colliding_edges(
        self, seqr: GtspSequencer, res: SequenceResult, checker: MotionChecker, n_holes: int
    ) -> SequenceResult:
        """Lazy collision checking: penalise tour edges whose straight segment collides
        (checked ``LAZY_COARSENESS`` times coarser than the set resolution), re-sequence."""
        o = self.options
        coarse = checker.coarser(LAZY_COARSENESS)
        started = time.perf_counter()
        for k in range(LAZY_ROUNDS):
            if time.perf_counter() - started > LAZY_BUDGET_SHARE * o.budget_s(n_holes):
                break
            path = [0, *(res.nodes or []), 0]
            penalties = {}
            for u, v in itertools.pairwise(path):
                key = (min(u, v), max(u, v))
                if key not in self._edge_free:
                    self._edge_free[key] = coarse.segment_free(seqr.nodes[u], seqr.nodes[v])
                if not self._edge_free[key] and (u, v) not in seqr.learned:
                    penalties[(u, v)] = DETOUR_FACTOR * seqr.G[u, v] + DETOUR_EXTRA_S
            checker.checks += coarse.checks
            coarse.checks = 0
            if not penalties:
                break
            seqr.learn(penalties)
            budget = o.budget_s(n_holes) * REFINE_SHARE
            res = seqr.solve(budget, o.seed + 100 + k, o.effort, warm=res.nodes, repair=True)
        return res

    def _sequence_and_paths(
        self,
        home: NDArray[np.float64],
        cands: list[HoleCandidates],
        limits: JointLimits,
        cache: SegmentCache,
        timings: dict[str, float],
    ) -> tuple[_Route, list[Segment], SequenceResult, int]:
        """Sequence, avoid colliding edges, plan the segments, feed measured detours back."""
        o = self.options
        t = time.perf_counter()
        self.progress("sequence", 0, 1)
        self._edge_free: dict[tuple[int, int], bool] = {}
        if self.sequencer is not None:
            res = self.sequencer(home, cands, limits)
            seqr = None
        else:
            seqr = GtspSequencer(home, [c.q for c in cands], limits, o.nodes_per_hole, o.sequencer)
            res = seqr.solve(o.budget_s(len(cands)), o.seed, o.effort)
            res = self._avoid_colliding_edges(seqr, res, cache.checker, len(cands))
        self.progress("sequence", 1, 1)
        timings["sequence"] = time.perf_counter() - t
        rounds = 0
        measured_pairs: set[tuple[int, int]] = set()
        while True:
            route = self._route(cands, res)
            segments = self._segments(home, route, cache)
            if seqr is None or res.nodes is None or rounds >= o.refine_rounds:
                return route, segments, res, rounds
            path_nodes = [0, *res.nodes, 0]
            measured = {
                (path_nodes[k], path_nodes[k + 1]): seg.motion.duration
                for k, seg in enumerate(segments)
                if seg.path.planned and (path_nodes[k], path_nodes[k + 1]) not in measured_pairs
            }
            if not measured:
                return route, segments, res, rounds
            rounds += 1
            t = time.perf_counter()
            measured_pairs.update(measured)
            measured_pairs.update((v, u) for u, v in measured)
            seqr.learn(measured)
            budget = o.budget_s(len(cands)) * REFINE_SHARE
            new = seqr.solve(budget, o.seed + rounds, o.effort, warm=res.nodes, repair=True)
            timings["sequence"] += time.perf_counter() - t
            if new.nodes == res.nodes:
                return route, segments, new, rounds
            res = new

    def _stops(
        self, arm: ArmLike, route: _Route, segments: list[Segment]
    ) -> tuple[list[Stop], list[TimedMotion | Dwell], float]:
        o = self.options
        timeline: list[TimedMotion | Dwell] = []
        stops: list[Stop] = []
        clock = 0.0
        for k, seg in enumerate(segments):
            timeline.append(seg.motion)
            clock += seg.motion.duration
            if k == len(route.hole_ids):
                break
            q = route.q[k]
            T = arm.fk(q, "tcp")
            pose = {
                "xyz": [float(v) for v in T[:3, 3]],
                "quat_xyzw": [float(v) for v in Rotation.from_matrix(T[:3, :3]).as_quat()],
            }
            stops.append(
                Stop(
                    route.hole_ids[k],
                    tuple(float(v) for v in q),
                    clock,
                    o.dwell_s,
                    pose,
                    route.branch[k],
                )
            )
            timeline.append(Dwell(q, o.dwell_s))
            clock += o.dwell_s
        return stops, timeline, clock

    def plan(self, cell: CellLike) -> Tour:
        """Plan the tour of ``cell`` (see module docstring). Raises :class:`PlanningError`."""
        o = self.options
        started = time.perf_counter()
        timings: dict[str, float] = {}
        arm = cell.build_arm()
        limits = JointLimits.from_arm(arm)
        home = self._home(arm, cell)
        checker = MotionChecker(arm, np.radians(o.joint_step_deg), o.tcp_step_m)
        cache = SegmentCache(
            checker, limits, o.seed, o.segment_time_s, o.dt, o.pass_through_waypoints
        )
        t = time.perf_counter()
        cands, left = self._viewpoints(arm, cell)
        timings["viewpoints"] = time.perf_counter() - t
        route, segments, seq, rounds = self._sequence_and_paths(home, cands, limits, cache, timings)
        timings["paths"] = cache.path_time_s
        t = time.perf_counter()
        stops, timeline, cycle = self._stops(arm, route, segments)
        trajectory = sample_timeline(timeline, o.dt)
        self.progress("timing", 1, 1)
        timings["timing"] = cache.timing_time_s + time.perf_counter() - t
        settings = o.to_dict() | {
            "sequencer": self.sequencer_name,
            "sequence_cost_s": seq.cost_s,
            "sequence_hit_time_limit": seq.hit_time_limit,
            "refine_rounds_used": rounds,
            "ompl_segments": sum(s.path.planned for s in segments),
            "collision_checks": checker.checks,
        }
        return Tour(
            cell_name=cell.name,
            cell_sha256=cell_sha256(cell),
            robot_model=cell.robot.model,
            joint_names=tuple(arm.joint_names),
            home_q=tuple(float(v) for v in home),
            stops=stops,
            left_out=left,
            dt=o.dt,
            trajectory=trajectory,
            cycle_time_s=cycle,
            planning_time_s=time.perf_counter() - started,
            timings_s=timings,
            settings=settings,
        )


def plan_tour(
    cell: CellLike, options: Options | None = None, progress: ProgressCallback | None = None
) -> Tour:
    """Plan an inspection tour of every reachable hole of ``cell`` (see :class:`TourPlanner`)."""
    return TourPlanner(options, progress).plan(cell)
