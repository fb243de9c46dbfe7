"""The tour planner: viewpoints → sequence → paths → timing → :class:`~planner.tour.Tour`.

``plan_tour(cell, options)`` takes any object shaped like ``cell.config.CellConfig``
(:class:`planner.protocols.CellLike`); the planner never imports :mod:`cell`.
Library code reports progress through an optional callback
``progress(stage, done, total)`` and logs with :mod:`logging`.
"""

from __future__ import annotations

import hashlib
import logging
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from planner.errors import NoReachableHoleError, StartConfigurationError, UnreachableHoleError
from planner.options import Options
from planner.paths import MotionChecker, SegmentPath, SegmentPlanner, seed_ompl
from planner.protocols import ArmLike, CellLike
from planner.sequence import SequenceResult, sequence
from planner.timing import JointLimits, TimedMotion, rest_to_rest, time_path
from planner.tour import LeftOut, Stop, Tour
from planner.trajectory import Dwell, sample_timeline
from planner.viewpoints import HoleCandidates, hole_candidates

log = logging.getLogger(__name__)

ProgressCallback = Callable[[str, int, int], None]
STAGES = ("viewpoints", "sequence", "paths", "timing")


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


@dataclass(frozen=True)
class _Route:
    hole_ids: list[str]
    q: NDArray[np.float64]  # (n, dof) stop configurations in order
    branch: list[int]
    candidates: list[HoleCandidates]


class TourPlanner:
    """Plans inspection tours with fixed :class:`Options`; :meth:`plan` does one cell."""

    def __init__(
        self, options: Options | None = None, progress: ProgressCallback | None = None
    ) -> None:
        self.options = options or Options()
        self.progress = progress or _no_progress

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

    def _sequence(
        self, home: NDArray[np.float64], cands: list[HoleCandidates], limits: JointLimits
    ) -> tuple[_Route, SequenceResult]:
        o = self.options
        self.progress("sequence", 0, 1)
        res = sequence(
            home,
            [c.q for c in cands],
            limits,
            time_budget_s=o.budget_s(len(cands)),
            seed=o.seed,
            nodes_per_hole=o.nodes_per_hole,
            effort=o.effort,
        )
        self.progress("sequence", 1, 1)
        route = _Route(
            hole_ids=[cands[h].hole_id for h in res.order],
            q=np.array([cands[h].q[c] for h, c in zip(res.order, res.choice, strict=True)]),
            branch=[int(cands[h].branch[c]) for h, c in zip(res.order, res.choice, strict=True)],
            candidates=[cands[h] for h in res.order],
        )
        return route, res

    def _paths(
        self, home: NDArray[np.float64], route: _Route, checker: MotionChecker, limits: JointLimits
    ) -> list[SegmentPath]:
        seed_ompl(self.options.seed)
        planner = SegmentPlanner(checker, limits.lower, limits.upper)
        points = [home, *route.q, home]
        names = ["home", *route.hole_ids, "home"]
        paths = []
        for k in range(len(points) - 1):
            paths.append(
                planner.plan(
                    points[k], points[k + 1], self.options.segment_time_s, (names[k], names[k + 1])
                )
            )
            self.progress("paths", k + 1, len(points) - 1)
        return paths

    def _timing(
        self, paths: list[SegmentPath], checker: MotionChecker, limits: JointLimits
    ) -> list[TimedMotion]:
        motions = []
        for k, path in enumerate(paths):
            if path.planned:
                motions.append(
                    time_path(path.waypoints, limits, checker.polyline_free, self.options.dt)
                )
            else:
                motions.append(rest_to_rest(path.waypoints[0], path.waypoints[-1], limits))
            self.progress("timing", k + 1, len(paths))
        return motions

    def plan(self, cell: CellLike) -> Tour:
        """Plan the tour of ``cell`` (see module docstring). Raises :class:`PlanningError`."""
        o = self.options
        started = time.perf_counter()
        timings: dict[str, float] = {}
        arm = cell.build_arm()
        limits = JointLimits.from_arm(arm)
        home = self._home(arm, cell)
        checker = MotionChecker(arm, np.radians(o.joint_step_deg), o.tcp_step_m)

        t = time.perf_counter()
        cands, left = self._viewpoints(arm, cell)
        timings["viewpoints"] = time.perf_counter() - t
        t = time.perf_counter()
        route, seq = self._sequence(home, cands, limits)
        timings["sequence"] = time.perf_counter() - t
        t = time.perf_counter()
        paths = self._paths(home, route, checker, limits)
        timings["paths"] = time.perf_counter() - t
        t = time.perf_counter()
        motions = self._timing(paths, checker, limits)
        timeline: list[TimedMotion | Dwell] = []
        stops: list[Stop] = []
        clock = 0.0
        for k, motion in enumerate(motions):
            timeline.append(motion)
            clock += motion.duration
            if k < len(route.hole_ids):
                q = route.q[k]
                T = arm.fk(q, "tcp")
                pose = {
                    "xyz": [float(v) for v in T[:3, 3]],
                    "quat_xyzw": [float(v) for v in Rotation.from_matrix(T[:3, :3]).as_quat()],
                }
                stops.append(
                    Stop(
                        hole_id=route.hole_ids[k],
                        q=tuple(float(v) for v in q),
                        t=clock,
                        dwell_s=o.dwell_s,
                        tcp_pose=pose,
                        branch=route.branch[k],
                    )
                )
                timeline.append(Dwell(q, o.dwell_s))
                clock += o.dwell_s
        trajectory = sample_timeline(timeline, o.dt)
        timings["timing"] = time.perf_counter() - t
        planning = time.perf_counter() - started
        settings = o.to_dict() | {
            "sequencer": "lns",
            "sequence_cost_s": seq.cost_s,
            "sequence_hit_time_limit": seq.hit_time_limit,
            "ompl_segments": sum(p.planned for p in paths),
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
            cycle_time_s=clock,
            planning_time_s=planning,
            timings_s=timings,
            settings=settings,
        )


def plan_tour(
    cell: CellLike, options: Options | None = None, progress: ProgressCallback | None = None
) -> Tour:
    """Plan an inspection tour of every reachable hole of ``cell`` (see :class:`TourPlanner`)."""
    return TourPlanner(options, progress).plan(cell)
