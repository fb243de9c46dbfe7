"""Batch collision checks of many straight joint motions at once.

:class:`BatchEdgeChecker` samples each motion like :class:`planner.paths.MotionChecker`
(joint and TCP steps; the same counts, in numpy for all motions at once), orders the
samples coarse to fine, and hands all motions to Pinocchio's
``computeCollisionsInParallel`` (:class:`robots.collision_batch.BatchCollision`: a pool
of coal's dynamic AABB trees with the requests of the arm's exact pairs), which stops
each motion at its first collision, so the answers equal ``Arm.in_collision`` sample by
sample. An arm without a Pinocchio collision model (a stand-in in tests) is checked one
configuration at a time through ``in_collision``.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from planner.paths import MotionChecker, _interpolation_order
from planner.sampling import interior_samples, motion_counts
from robots.collision_batch import BatchCollision


class BatchEdgeChecker:
    """Checks lists of straight motions (joint limits and collisions) in one call.

    ``threads``: Pinocchio worker threads (default: the cores this process may use).
    """

    def __init__(self, checker: MotionChecker, threads: int | None = None) -> None:
        self.checker = checker
        self.batch = BatchCollision.of_arm(checker.arm, threads)
        self.threads = self.batch.threads if self.batch else 1
        self.checks = 0

    def _counts(self, A: NDArray[np.float64], B: NDArray[np.float64]) -> NDArray[np.int64]:
        """Steps per motion (the rule and arithmetic of :meth:`MotionChecker.samples`)."""
        c = self.checker
        return motion_counts(c.arm, c.joint_step, c.tcp_step, A, B)

    def free(self, starts: NDArray[np.float64], ends: NDArray[np.float64]) -> NDArray[np.bool_]:
        """For each row pair (``starts[i]`` → ``ends[i]``, rad): True when the straight motion
        is within the limits and free of collision at the checker's resolution."""
        A, B = np.asarray(starts, dtype=float), np.asarray(ends, dtype=float)
        if not len(A):
            return np.zeros(0, dtype=bool)
        n = self._counts(A, B)
        # every motion's interior samples, coarse to fine (the order of MotionChecker), in one
        # array: row j of motion i is A_i + t (B_i - A_i) with t = k / n_i as np.linspace
        Q, bounds = interior_samples(A, B, n, _interpolation_order)
        sizes = n - 1
        lo, hi = self.checker.lower, self.checker.upper
        row_in = np.all((lo <= Q) & (hi >= Q), axis=1)
        inner_in = np.ones(len(A), dtype=bool)
        has = sizes > 0
        inner_in[has] = np.logical_and.reduceat(row_in, bounds[:-1][has])
        last = A + 1.0 * (B - A)  # the last sample of np.linspace's motion
        ends_in = np.all((lo <= A) & (hi >= A) & (last >= lo) & (last <= hi), axis=1)
        out = np.zeros(len(A), dtype=bool)
        todo = np.flatnonzero(inner_in & ends_in)
        if not len(todo):
            return out
        # the motions share their ends (each node is the end of many): every distinct end
        # configuration is checked once, each motion's interior samples in its own trajectory
        uniq, which = np.unique(np.vstack([A[todo], B[todo]]), axis=0, return_inverse=True)
        which = which.reshape(2, len(todo))
        QT = Q.T  # (dof, samples), Fortran order: each motion's columns are one block
        inner = [QT[:, bounds[i] : bounds[i + 1]] for i in todo]
        self.checks += len(uniq) + int(sizes[todo].sum())
        end_free = ~self._hits([e[:, None] for e in uniq])
        inner_free = ~self._hits(inner)
        out[todo] = end_free[which[0]] & end_free[which[1]] & inner_free
        return out

    def _hits(self, trajs: list[NDArray[np.float64]]) -> NDArray[np.bool_]:
        """For each trajectory (columns: configurations, (dof, m)): True when one collides."""
        if self.batch is not None:
            return self.batch.any_hit(trajs)
        arm = self.checker.arm  # a stand-in without a Pinocchio model: one at a time
        return np.array([any(arm.in_collision(q) for q in Q.T) for Q in trajs], dtype=bool)
