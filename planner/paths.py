"""Collision-free joint paths between stops: the straight segment, else OMPL.

:class:`MotionChecker` checks a motion at a set resolution: no joint moves more
than ``joint_step_rad`` and the TCP no more than ``tcp_step_m`` between two
checked configurations. :class:`SegmentPlanner` returns the straight joint
segment when it is free, else plans with OMPL's RRT-Connect (validity by the
arm's collision check, motions by :class:`MotionChecker`) and shortcuts and
simplifies the result.

Planning first uses motion checks ``COARSE_FACTOR`` times coarser than the set
resolution (most of the planner's checks are on edges it then discards) and
validates the simplified path at the set resolution; only when that fails is
the segment planned again at the set resolution. Every returned path is free
at the set resolution.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from numpy.typing import NDArray
from ompl import base as ob
from ompl import geometric as og
from ompl import util as ou

from planner.errors import SegmentPlanningError
from planner.protocols import ArmLike
from planner.sampling import interior_samples, motion_counts, tcp_positions

log = logging.getLogger(__name__)

_seeded: list[int] = []

#: motion checks during the first planning attempt are this much coarser
COARSE_FACTOR = 4.0


def seed_ompl(seed: int) -> None:
    """Seed OMPL's random numbers (effective once per process, before any sampling)."""
    if not _seeded:
        ou.setLogLevel(ou.LogLevel.LOG_ERROR)
        ou.RNG.setSeed(int(seed) + 1)  # OMPL treats 0 as "no seed"
        _seeded.append(int(seed))


def _interpolation_order(n: int) -> NDArray[np.int64]:
    """Indices 1..n-1 coarse to fine (a van der Corput order), so collisions show early.

    Cached per ``n`` (read-only arrays: many motions share a sample count)."""
    return _order_of(int(n))


@lru_cache(maxsize=4096)
def _order_of(n: int) -> NDArray[np.int64]:
    order, seen = [], set()
    step = 1 << max(int(np.ceil(np.log2(max(n, 2)))), 1)
    while step >= 1:
        for i in range(step, n, step):
            if i not in seen:
                seen.add(i)
                order.append(i)
        step //= 2
    out = np.array(order, dtype=np.int64)
    out.flags.writeable = False
    return out


class MotionChecker:
    """Collision checks of configurations and straight joint motions at a resolution."""

    def __init__(self, arm: ArmLike, joint_step_rad: float, tcp_step_m: float) -> None:
        self.arm = arm
        self.joint_step = joint_step_rad
        self.tcp_step = tcp_step_m
        self.checks = 0
        self.lower = np.asarray(arm.lower, dtype=float) - 1e-9
        self.upper = np.asarray(arm.upper, dtype=float) + 1e-9

    def coarser(self, factor: float) -> MotionChecker:
        """A checker on the same arm with ``factor`` times larger steps."""
        return MotionChecker(self.arm, self.joint_step * factor, self.tcp_step * factor)

    def state_free(self, q: NDArray[np.float64]) -> bool:
        """True when ``q`` is within limits and free of collision."""
        self.checks += 1
        return self._inside(q) and not self.arm.in_collision(q)

    def _inside(self, Q: NDArray[np.float64]) -> bool:
        """True when every configuration (row) lies within the joint limits."""
        return bool(
            np.all(np.greater_equal(Q, self.lower)) and np.all(np.less_equal(Q, self.upper))
        )

    def samples(self, q_a: NDArray[np.float64], q_b: NDArray[np.float64]) -> NDArray[np.float64]:
        """Configurations on the straight segment, ends included, at the checker's resolution."""
        n = max(int(np.ceil(np.abs(q_b - q_a).max() / self.joint_step)), 1)
        for _ in range(8):
            t = np.linspace(0.0, 1.0, n + 1)[:, None]
            Q = q_a + t * (q_b - q_a)
            tcp = tcp_positions(self.arm, Q)
            worst = np.linalg.norm(np.diff(tcp, axis=0), axis=1).max()
            if worst <= self.tcp_step:
                return Q
            n = int(np.ceil(n * worst / self.tcp_step * 1.05))
        return Q

    def segment_free(
        self, q_a: NDArray[np.float64], q_b: NDArray[np.float64], ends: bool = False
    ) -> bool:
        """True when the straight motion ``q_a`` to ``q_b`` is free (ends checked if ``ends``)."""
        Q = self.samples(np.asarray(q_a, float), np.asarray(q_b, float))
        if ends and not (self.state_free(Q[0]) and self.state_free(Q[-1])):
            return False
        if not self._inside(Q):
            return False
        order = _interpolation_order(len(Q) - 1)
        self.checks += len(order)
        return not self._any_collides(Q[order])

    def _any_collides(self, Q: NDArray[np.float64]) -> bool:
        """True when a row of ``Q`` collides, checked in row order up to the first hit: one
        batch call where the arm offers it (``robots.Arm.in_collision_any``), else one by one.
        """
        batch = getattr(self.arm, "in_collision_any", None)
        if batch is not None:
            return bool(batch(Q))
        return any(self.arm.in_collision(q) for q in Q)

    def polyline_free(self, Q: NDArray[np.float64]) -> bool:
        """True when the motion through the rows of ``Q`` (straight between rows) is free.

        The rows and every segment's samples within the limits, and none colliding; checked
        in the order row 0, segment 1 coarse to fine, row 1, segment 2, ... (all segments'
        samples made at once, :mod:`planner.sampling`; the same samples and answer as checking
        one segment at a time).
        """
        Q = np.asarray(Q, dtype=float)
        if len(Q) < 2:
            return self.state_free(Q[0])
        A, B = Q[:-1], Q[1:]
        n = motion_counts(self.arm, self.joint_step, self.tcp_step, A, B)
        inner, bounds = interior_samples(A, B, n, _interpolation_order)
        last = A + 1.0 * (B - A)  # each segment's last sample (np.linspace's)
        if not (self._inside(Q) and self._inside(inner) and self._inside(last)):
            return False
        # row i goes before segment i's samples: its position is i + the samples before it
        at = np.arange(len(Q)) + bounds
        seq = np.empty((len(Q) + len(inner), Q.shape[1]))
        mask = np.zeros(len(seq), dtype=bool)
        mask[at] = True
        seq[mask] = Q
        seq[~mask] = inner
        self.checks += len(seq)
        return not self._any_collides(seq)


class _MotionValidator(ob.MotionValidator):
    def __init__(self, si: ob.SpaceInformation, checker: MotionChecker, dof: int) -> None:
        super().__init__(si)
        self.checker = checker
        self.dof = dof

    def checkMotion(self, s1: ob.State, s2: ob.State) -> bool:
        a = np.array([s1[i] for i in range(self.dof)])
        b = np.array([s2[i] for i in range(self.dof)])
        return bool(self.checker.segment_free(a, b) and self.checker.state_free(b))


@dataclass(frozen=True)
class SegmentPath:
    """A collision-free joint path (m, dof) rad, straight between rows; ``planned`` if not the
    straight segment (by OMPL, or ``via_roadmap``: through roadmap configurations)."""

    waypoints: NDArray[np.float64]
    planned: bool
    via_roadmap: bool = False


class _Space:
    """OMPL space information whose motions are checked by one :class:`MotionChecker`."""

    def __init__(
        self, checker: MotionChecker, lower: NDArray[np.float64], upper: NDArray[np.float64]
    ) -> None:
        self.checker = checker
        self.dof = len(lower)
        self.space = ob.RealVectorStateSpace(self.dof)
        bounds = ob.RealVectorBounds(self.dof)
        for i in range(self.dof):
            bounds.setLow(i, float(lower[i]))
            bounds.setHigh(i, float(upper[i]))
        self.space.setBounds(bounds)
        self.si = ob.SpaceInformation(self.space)
        self.si.setStateValidityChecker(self._valid)
        self.validator = _MotionValidator(self.si, checker, self.dof)
        self.si.setMotionValidator(self.validator)
        self.si.setup()

    def _valid(self, state: ob.State) -> bool:
        return bool(self.checker.state_free(np.array([state[i] for i in range(self.dof)])))

    def _state(self, q: NDArray[np.float64]) -> ob.State:
        s = self.si.allocState()
        s[0 : self.dof] = [float(v) for v in q]
        return s

    def solve(
        self, q_a: NDArray[np.float64], q_b: NDArray[np.float64], time_s: float
    ) -> NDArray[np.float64] | None:
        """RRT-Connect then simplification; the waypoints (m, dof) or ``None`` if unsolved."""
        pdef = ob.ProblemDefinition(self.si)
        pdef.setStartAndGoalStates(self._state(q_a), self._state(q_b))
        planner = og.RRTConnect(self.si)
        planner.setProblemDefinition(pdef)
        planner.setup()
        planner.solve(ob.timedPlannerTerminationCondition(time_s))
        if not pdef.hasExactSolution():
            return None
        path = pdef.getSolutionPath()
        simplifier = og.PathSimplifier(self.si)
        simplifier.simplify(path, min(time_s, 0.5))
        Q = np.array(
            [[path.getState(k)[i] for i in range(self.dof)] for k in range(path.getStateCount())]
        )
        Q[0], Q[-1] = q_a, q_b
        return Q


class SegmentPlanner:
    """Straight segment when free, else a given detour, else RRT-Connect + shortcutting."""

    def _shortcut(self, Q: NDArray[np.float64]) -> NDArray[np.float64]:
        """Greedy shortcut of a free polyline: from each kept row, jump to the farthest row
        that the straight motion reaches freely (the result stays free at the resolution)."""
        keep, i = [0], 0
        while i < len(Q) - 1:
            j = len(Q) - 1
            while j > i + 1 and not self.checker.segment_free(Q[i], Q[j]):
                j -= 1
            keep.append(j)
            i = j
        return Q[keep]

    def __init__(
        self, checker: MotionChecker, lower: NDArray[np.float64], upper: NDArray[np.float64]
    ) -> None:
        self.checker = checker
        self.coarse = _Space(checker.coarser(COARSE_FACTOR), lower, upper)
        self.fine = _Space(checker, lower, upper)

    def plan(
        self,
        q_a: NDArray[np.float64],
        q_b: NDArray[np.float64],
        time_s: float,
        names: tuple[str, str],
        via: NDArray[np.float64] | None = None,
        straight_free: bool = False,
    ) -> SegmentPath:
        """A free path ``q_a`` to ``q_b``, else :class:`SegmentPlanningError` naming ``names``.

        ``via`` (rows, rad): a detour through known free configurations, tried (validated at
        the set resolution, shortcut where straight motions are free) before OMPL.
        ``straight_free``: the caller checked the straight motion at the set resolution.
        """
        if straight_free or self.checker.segment_free(q_a, q_b):
            return SegmentPath(np.array([q_a, q_b]), planned=False)
        Q: NDArray[np.float64] | None
        if via is not None and len(via):
            Q = np.vstack([q_a, via, q_b])
            if self.checker.polyline_free(Q):
                return SegmentPath(self._shortcut(Q), planned=True, via_roadmap=True)
        Q = self.coarse.solve(q_a, q_b, time_s)
        self.checker.checks += self.coarse.checker.checks
        self.coarse.checker.checks = 0
        if Q is None or not self.checker.polyline_free(Q):
            Q = self.fine.solve(q_a, q_b, time_s)
        if Q is None:
            raise SegmentPlanningError(*names, f"RRT-Connect found no path in {time_s:g} s")
        log.info("segment %s -> %s: OMPL path with %d waypoints", names[0], names[1], len(Q))
        return SegmentPath(Q, planned=True)
