"""The tour planner: viewpoints → sequence → paths → timing → :class:`~planner.tour.Tour`.

``plan_tour(cell, options)`` takes any object shaped like ``cell.config.CellConfig``
(:class:`planner.protocols.CellLike`); the planner never imports :mod:`cell`.
Library code reports progress through an optional callback
``progress(stage, done, total)`` and logs with :mod:`logging`.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable
from typing import cast

import numpy as np
from numpy.typing import NDArray

from planner.cell_identity import cell_sha256, check_tour_for_cell
from planner.edge_check import BatchEdgeChecker
from planner.errors import (
    NoReachableHoleError,
    SegmentPlanningError,
    StartConfigurationError,
    UnreachableHoleError,
)
from planner.helper import Helper
from planner.lazy_edges import PROBE_COARSENESS, REFINE_SHARE, LazyEdgeChecks
from planner.lns import COMPILED_ABOVE
from planner.lns_compile import compile_kernels
from planner.options import Options
from planner.paths import MotionChecker
from planner.protocols import ArmLike, CellLike
from planner.roadmap import Roadmap, build_roadmap, detour_costs
from planner.route import Route, route_stops
from planner.sampling import tcp_positions
from planner.segments import Segment, SegmentCache
from planner.sequence import GtspSequencer, SequenceResult
from planner.shared import SharedPlan, options_key, unpack
from planner.timing import JointLimits
from planner.tour import LeftOut, Tour
from planner.trajectory import sample_timeline
from planner.viewpoints import HoleCandidates, ViewSettings, all_hole_candidates

__all__ = [
    "STAGES",
    "ProgressCallback",
    "Sequencer",
    "TourPlanner",
    "cell_sha256",
    "check_tour_for_cell",
    "plan_tour",
]

log = logging.getLogger(__name__)

ProgressCallback = Callable[[str, int, int], None]
#: a replacement sequencer: (home q, candidates per hole, limits) -> SequenceResult
Sequencer = Callable[[NDArray[np.float64], list[HoleCandidates], JointLimits], SequenceResult]
STAGES = ("viewpoints", "sequence", "paths", "timing")
#: a motion OMPL could not plan costs this much (s) and the tour is re-sequenced, this many times
UNSOLVED_COST_S = 1000.0
MAX_UNSOLVED = 5
#: roadmap edge checks are this many times coarser than the set motion resolution (they
#: only prove collisions: a motion found free there is checked again at the set resolution
#: when a tour uses it; lazy checks at 3× coarser missed 1 cm plates and thin posts on the
#: cluttered cells and left those detours to OMPL's random state). 6× (was 3×): the same
#: tours for frame seeds 0-3 and cluttered-20/40/80 seeds 0-1, 1.5-2 s less CPU per start
ROADMAP_COARSENESS = 6.0


def _no_progress(stage: str, done: int, total: int) -> None:
    log.debug("%s %d/%d", stage, done, total)


class TourPlanner(LazyEdgeChecks):
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
        s = ViewSettings(
            cell.tool.standoff_m, o.roll_step_deg, o.tilt_deg, o.tilt_azimuths, o.fallback_tilt_deg
        )
        each = all_hole_candidates(
            arm, holes, s, getattr(self, "_helper", None),
            lambda done: self.progress("viewpoints", done, len(holes)),
            lambda: self._load_kernels(len(holes)),
        )  # fmt: skip
        found, left = [], []
        for hole, (c, tilted) in zip(holes, each, strict=True):
            if tilted:
                log.info("hole %s: viewed up to %g deg off its axis", hole.id, o.fallback_tilt_deg)
            if c.ok:
                found.append(c)
            else:
                left.append(LeftOut(hole.id, c.reason or "no viewpoint"))
        reasons = {h.hole_id: h.reason for h in left}
        if not found:
            raise NoReachableHoleError(reasons)
        if left and o.strict:
            raise UnreachableHoleError(reasons)
        for h in left:
            log.warning("hole %s left out: %s", h.hole_id, h.reason)
        return found, left

    def _load_kernels(self, n_holes: int) -> None:
        """Load the search's compiled kernels (Numba's cache: ~1 s of CPU in a fresh process)
        while the helper process computes viewpoints, where the search will use them."""
        if self.sequencer is None and self.options.sequencer == "lns" and n_holes > COMPILED_ABOVE:
            compile_kernels()

    def _route(self, cands: list[HoleCandidates], res: SequenceResult) -> Route:
        pairs = list(zip(res.order, res.choice, strict=True))
        return Route(
            hole_ids=[cands[h].hole_id for h, _ in pairs],
            q=np.array([cands[h].q[c] for h, c in pairs]),
            branch=[int(cands[h].branch[c]) for h, c in pairs],
            candidates=[cands[h] for h, _ in pairs],
        )

    def _segments(
        self,
        home: NDArray[np.float64],
        route: Route,
        cache: SegmentCache,
        seqr: GtspSequencer | None = None,
        nodes: list[int] | None = None,
    ) -> list[Segment]:
        points = [home, *route.q, home]
        names = ["home", *route.hole_ids, "home"]
        path = [0, *nodes, 0] if seqr is not None and nodes is not None else None
        out = []
        for k in range(len(points) - 1):
            via = None
            known = False  # checked free at the set resolution by the lazy rounds' batch
            if path is not None:
                assert seqr is not None  # path is only built with a sequencer (above)
                hops = self._roadmap.via(path[k], path[k + 1])
                via = None if not hops else seqr.nodes[hops]
                u, v = path[k], path[k + 1]
                known = self._edge_free.get((min(u, v), max(u, v))) is True
            try:
                pair = (names[k], names[k + 1])
                out.append(cache.get(points[k], points[k + 1], pair, via, known))
            except SegmentPlanningError as exc:
                exc.nodes = None if path is None else (path[k], path[k + 1])
                raise
            self.progress("paths", k + 1, len(points) - 1)
        return out

    def _build_roadmap(self, seqr: GtspSequencer, checker: MotionChecker) -> None:
        """Batch-check the motions between near nodes (``ROADMAP_COARSENESS`` times coarser
        than the set resolution); colliding ones cost their roadmap detour."""
        k = self.options.roadmap_neighbours
        self._roadmap = Roadmap()
        self._batch = BatchEdgeChecker(checker)
        if k <= 0:
            return
        coarse = BatchEdgeChecker(checker.coarser(ROADMAP_COARSENESS))
        helper = getattr(self, "_helper", None)
        held = helper is not None and seqr.helper_G is seqr.G  # its neighbour lists: half there
        self._roadmap = build_roadmap(seqr.nodes, seqr.G, seqr.owner, coarse, k, helper, held)
        checker.checks += coarse.checks
        blocked = []
        for (u, v), free in self._roadmap.free.items():
            if not free:  # a collision at a coarse sample is one at the set resolution too
                self._edge_free[(u, v)] = False
                blocked += [(u, v), (v, u)]
        seqr.learn(detour_costs(self._roadmap, seqr.G, blocked, helper))

    def _sequence_and_paths(
        self,
        shared: SharedPlan,
        limits: JointLimits,
        cache: SegmentCache,
        timings: dict[str, float],
    ) -> tuple[Route, list[Segment], SequenceResult, int]:
        """Sequence, avoid colliding edges, plan the segments, feed measured detours back."""
        o = self.options
        home, cands = shared.home, shared.candidates
        t = time.perf_counter()
        self.progress("sequence", 0, 1)
        self._edge_free = shared.edge_free
        self._roadmap = shared.roadmap
        self._lazy_rounds = 0
        self._coarse_free: set[tuple[int, int]] = set()  # free at the coarse resolution
        self._siblings = 0
        self._corridor = 0
        seqr = shared.sequencer
        if self.sequencer is not None or seqr is None:
            # None only for a shared plan prepared with a replacement sequencer (the options
            # do not record it): the call then fails as it always did
            res = cast(Sequencer, self.sequencer)(home, cands, limits)
            seqr = None
        else:
            self._batch = BatchEdgeChecker(cache.checker)
            self._coarse_batch = BatchEdgeChecker(cache.checker.coarser(ROADMAP_COARSENESS))
            self._probe_batch = BatchEdgeChecker(cache.checker.coarser(PROBE_COARSENESS))
            seen: list[list[int]] = []
            res = seqr.solve(o.budget_s(len(cands)), o.seed, o.effort, record=seen)
            res = self._avoid_colliding_edges(seqr, res, cache.checker, len(cands), seen)
        self.progress("sequence", 1, 1)
        timings["sequence"] = timings.get("sequence", 0.0) + time.perf_counter() - t
        rounds = 0
        measured_pairs: set[tuple[int, int]] = set()
        unsolved = 0
        while True:
            route = self._route(cands, res)
            try:
                segments = self._segments(home, route, cache, seqr, res.nodes)
            except SegmentPlanningError as exc:
                pair = getattr(exc, "nodes", None)
                if seqr is None or pair is None or unsolved >= MAX_UNSOLVED:
                    raise
                unsolved += 1  # avoid that motion: re-sequence around it
                log.info("%s; re-sequencing without it", exc)
                seqr.learn({pair: UNSOLVED_COST_S})
                self._edge_free[(min(pair), max(pair))] = False
                budget = o.budget_s(len(cands)) * REFINE_SHARE
                seen = []
                res = seqr.solve(budget, o.seed + 200 + unsolved, o.effort, res.nodes, True, seen)
                res = self._avoid_colliding_edges(seqr, res, cache.checker, len(cands), seen)
                continue
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
            seen = []
            new = seqr.solve(budget, o.seed + rounds, o.effort, res.nodes, True, seen)
            new = self._avoid_colliding_edges(seqr, new, cache.checker, len(cands), seen)
            timings["sequence"] += time.perf_counter() - t
            if new.nodes == res.nodes:
                return route, segments, new, rounds
            res = new

    def prepare(self, cell: CellLike) -> SharedPlan:
        """The seed-independent part of planning ``cell`` (:mod:`planner.shared`): viewpoints,
        the GTSP's nodes and costs, the roadmap."""
        o = self.options
        cpu = time.process_time()
        arm = cell.build_arm()
        self._arm = arm
        limits = JointLimits.from_arm(arm)
        home = self._home(arm, cell)
        checker = MotionChecker(arm, np.radians(o.joint_step_deg), o.tcp_step_m)
        self._helper = Helper.start(len(cell.holes_in_cell()), arm=arm)
        try:
            t = time.perf_counter()
            cands, left = self._viewpoints(arm, cell)
            timings = {"viewpoints": time.perf_counter() - t}
            t = time.perf_counter()
            self._edge_free: dict[tuple[int, int], bool] = {}
            self._roadmap = Roadmap()
            seqr = None
            if self.sequencer is None:
                self.progress("sequence", 0, 1)
                # viewpoint positions (home's TCP first): the polish's task-space start
                xyz = np.vstack(
                    [tcp_positions(arm, home[None, :])] + [c.poses[0][:3, 3] for c in cands]
                )
                seqr = GtspSequencer(
                    home,
                    [c.q for c in cands],
                    limits,
                    o.nodes_per_hole,
                    o.sequencer,
                    positions_m=xyz,
                    helper=self._helper,
                )
                seqr.add_task_space_nodes()  # before the roadmap: their motions are checked too
                self._build_roadmap(seqr, checker)
            timings["sequence"] = time.perf_counter() - t
        finally:
            helper_cpu = self._helper.close() if self._helper is not None else 0.0
            self._helper = None
        return SharedPlan(
            cell_sha256(cell), options_key(o), home, cands, left, seqr, self._roadmap,
            self._edge_free, checker.checks, timings, time.process_time() - cpu + helper_cpu,
            helper_cpu,
        )  # fmt: skip

    def plan(self, cell: CellLike, shared: SharedPlan | bytes | None = None) -> Tour:
        """Plan the tour of ``cell`` (see module docstring). Raises :class:`PlanningError`.

        ``shared``: the seed-independent part from :meth:`prepare` (or :func:`pack`) of the
        same cell and options, any seed; this start then works on its own copy of it."""
        o = self.options
        started = time.perf_counter()
        if shared is None:
            shared = self.prepare(cell)
            arm = self._arm
        else:
            shared = unpack(shared)
            shared.check(cell_sha256(cell), o)
            arm = cell.build_arm()
        timings = dict(shared.timings_s)
        limits = JointLimits.from_arm(arm)
        home, left = shared.home, shared.left_out
        checker = MotionChecker(arm, np.radians(o.joint_step_deg), o.tcp_step_m)
        checker.checks = shared.collision_checks
        cache = SegmentCache(
            checker, limits, o.seed, o.segment_time_s, o.dt, o.pass_through_waypoints
        )
        route, segments, seq, rounds = self._sequence_and_paths(shared, limits, cache, timings)
        timings["paths"] = cache.path_time_s
        t = time.perf_counter()
        stops, timeline, cycle = route_stops(arm, route, segments, o.dwell_s)
        trajectory = sample_timeline(timeline, o.dt)
        self.progress("timing", 1, 1)
        timings["timing"] = cache.timing_time_s + time.perf_counter() - t
        settings = o.to_dict() | {
            "sequencer": self.sequencer_name,
            "sequence_cost_s": seq.cost_s,
            "sequence_hit_time_limit": seq.hit_time_limit,
            "refine_rounds_used": rounds,
            "ompl_segments": sum(s.path.planned and not s.path.via_roadmap for s in segments),
            "roadmap_segments": sum(s.path.via_roadmap for s in segments),
            "roadmap_edges_checked": self._roadmap.checked,
            "lazy_rounds": self._lazy_rounds,
            "lazy_siblings_blocked": self._siblings,
            "lazy_corridor_blocked": self._corridor,
            "roadmap_edges_blocked": sum(not f for f in self._roadmap.free.values()),
            "collision_checks": checker.checks,
            "helper_cpu_time_s": shared.helper_cpu_time_s,
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
