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

from collections.abc import Callable
from functools import partial
from typing import Any

import numpy as np
from numpy.typing import NDArray

from planner.helper import Helper, helper_arm
from planner.paths import MotionChecker, _interpolation_order
from planner.sampling import interior_samples, motion_counts
from robots.collision_batch import BatchCollision

#: with a helper process, each process checks at least this many motions (else one does all)
HELPER_MIN_MOTIONS = 500
#: ... in this many chunks, taken by whichever process is free (:meth:`BatchEdgeChecker._share`)
SHARE_CHUNKS = 32


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

    def free(
        self,
        starts: NDArray[np.float64],
        ends: NDArray[np.float64],
        helper: Helper | None = None,
    ) -> NDArray[np.bool_]:
        """For each row pair (``starts[i]`` → ``ends[i]``, rad): True when the straight motion
        is within the limits and free of collision at the checker's resolution.

        ``helper`` (:class:`planner.helper.Helper`): the interior samples are checked in
        chunks shared with the helper process (:meth:`_share`), each one configuration at a
        time (the same answers and counts as one process)."""
        A, B = np.asarray(starts, dtype=float), np.asarray(ends, dtype=float)
        out = np.zeros(len(A), dtype=bool)
        if not len(A):
            return out
        lo, hi = self.checker.lower, self.checker.upper
        last = A + 1.0 * (B - A)  # the last sample of np.linspace's motion
        ends_in = np.all((lo <= A) & (hi >= A) & (last >= lo) & (last <= hi), axis=1)
        idx = np.flatnonzero(ends_in)
        if not len(idx):
            return out
        collect = None
        if helper is not None and len(idx) >= 2 * HELPER_MIN_MOTIONS:
            inner_in, inner_free, sizes, collect = self._share(A[idx], B[idx], helper)
        else:
            inner_in, inner_free, sizes = self._interiors(A[idx], B[idx])
        # the motions share their ends (each node is the end of many): every distinct end
        # configuration is checked once, here, while the helper finishes its last chunks
        uniq, which = np.unique(np.vstack([A[idx], B[idx]]), axis=0, return_inverse=True)
        which = which.reshape(2, len(idx))
        end_free = ~self._hits([e[:, None] for e in uniq])
        if collect is not None:
            collect()
        self.checks += len(uniq) + int(sizes[inner_in].sum())
        out[idx] = end_free[which[0]] & end_free[which[1]] & inner_in & inner_free
        return out

    def _share(
        self, A: NDArray[np.float64], B: NDArray[np.float64], helper: Helper
    ) -> tuple[NDArray[np.bool_], NDArray[np.bool_], NDArray[np.int64], Callable[[], None]]:
        """:meth:`_interiors` of the motions ``A`` → ``B``, in ``SHARE_CHUNKS`` chunks (every
        ``SHARE_CHUNKS``-th motion: chunks of equal cost) that the helper takes from the last
        while this process takes them from the first, one configuration per call; a chunk
        not yet handed to the helper (its executor queues up to two ahead) when this process
        reaches it is done here. Returns the arrays, filled where this process worked, and the
        call that fills in the helper's chunks (waiting for them)."""
        c = self.checker
        chunks = [np.arange(j, len(A), SHARE_CHUNKS) for j in range(SHARE_CHUNKS)]
        futures = {
            j: helper.submit(interior_free, A[pos], B[pos], c.joint_step, c.tcp_step)
            for j, pos in reversed(list(enumerate(chunks)))
            if j > 0
        }
        whole = (np.empty(len(A), bool), np.empty(len(A), bool), np.empty(len(A), np.int64))

        def put(pos: NDArray[np.int64], got: tuple[NDArray[Any], ...]) -> None:
            for w, x in zip(whole, got, strict=True):
                w[pos] = x

        for j, pos in enumerate(chunks):
            f = futures.get(j)
            if f is not None and not f.cancel():
                break  # the helper has it (and every chunk after it)
            futures.pop(j, None)
            put(pos, self._interiors(A[pos], B[pos], one_at_a_time=True))

        def collect() -> None:
            for j, f in futures.items():
                pos = chunks[j]
                put(pos, Helper.result(f, partial(self._interiors, A[pos], B[pos], True)))

        return *whole, collect

    def _interiors(
        self, A: NDArray[np.float64], B: NDArray[np.float64], one_at_a_time: bool = False
    ) -> tuple[NDArray[np.bool_], NDArray[np.bool_], NDArray[np.int64]]:
        """Per motion: its interior samples within the limits; (where they are) free of
        collision, each motion's checked coarse to fine up to its first collision; their
        count. ``one_at_a_time``: one configuration per call, never the thread pool."""
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
        QT = Q.T  # (dof, samples), Fortran order: each motion's columns are one block
        todo = np.flatnonzero(inner_in)
        inner = [QT[:, bounds[i] : bounds[i + 1]] for i in todo]
        free = np.zeros(len(A), dtype=bool)
        free[todo] = ~self._hits(inner, one_at_a_time)
        return inner_in, free, sizes

    def _hits(
        self, trajs: list[NDArray[np.float64]], one_at_a_time: bool = False
    ) -> NDArray[np.bool_]:
        """For each trajectory (columns: configurations, (dof, m)): True when one collides."""
        if self.batch is not None and not one_at_a_time:
            return self.batch.any_hit(trajs)
        # one configuration per call (the pool's answers; its C++ loop costs ~40 % more CPU
        # per configuration on one thread), or a stand-in without a Pinocchio model
        check = (
            self.batch.collision.in_collision
            if self.batch is not None
            else self.checker.arm.in_collision
        )
        return np.array(
            [any(check(q) for q in np.ascontiguousarray(Q.T)) for Q in trajs], dtype=bool
        )


#: in the helper: its checker per resolution (made on its first chunk: a batch checker's
#: pool of broad phases costs ~10 ms)
_HELPER_CHECKERS: dict[tuple[int, float, float], BatchEdgeChecker] = {}


def interior_free(
    A: NDArray[np.float64], B: NDArray[np.float64], joint_step: float, tcp_step: float
) -> tuple[NDArray[np.bool_], NDArray[np.bool_], NDArray[np.int64]]:
    """:meth:`BatchEdgeChecker._interiors` of the helper process's arm (run there, one
    configuration at a time: :mod:`planner.helper`)."""
    arm = helper_arm()
    key = (id(arm), joint_step, tcp_step)
    if key not in _HELPER_CHECKERS:
        _HELPER_CHECKERS.clear()
        _HELPER_CHECKERS[key] = BatchEdgeChecker(MotionChecker(arm, joint_step, tcp_step), 1)
    return _HELPER_CHECKERS[key]._interiors(A, B, one_at_a_time=True)
