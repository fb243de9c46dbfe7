"""Batch collision checks of many straight joint motions at once.

:class:`BatchEdgeChecker` samples each motion like :class:`planner.paths.MotionChecker`
(joint and TCP steps), orders the samples coarse to fine, and hands all motions to
Pinocchio's ``computeCollisionsInParallel`` over a pool of broad-phase managers (coal's
dynamic AABB tree), which stops each motion at its first collision. The collision
requests are set up as in :class:`robots.collision.CollisionModel` (contacts on, GJK
from the default guess), so the answers equal ``Arm.in_collision`` sample by sample.
An arm without a Pinocchio collision model (a stand-in in tests) is checked one
configuration at a time through ``in_collision``.
"""

from __future__ import annotations

import os
from collections.abc import Sequence

import coal
import numpy as np
import pinocchio as pin
from numpy.typing import NDArray

from planner.paths import MotionChecker, _interpolation_order


def _pool(arm: object, threads: int) -> object | None:
    collision = getattr(arm, "collision", None)
    if collision is None or not hasattr(collision, "geom_model"):
        return None
    pool = pin.BroadPhaseManagerPool_DynamicAABBTreeCollisionManager(
        collision.model, collision.geom_model, threads
    )
    # the same requests as the arm's own checks, clearance margins included
    margins = [req.security_margin for req in collision.geom_data.collisionRequests]
    for gd in pool.getGeometryDatas():
        for req, margin in zip(gd.collisionRequests, margins, strict=True):
            req.enable_contact = True
            req.gjk_initial_guess = coal.GJKInitialGuess.DefaultGuess
            req.security_margin = margin
        for k, active in enumerate(collision.geom_data.activeCollisionPairs):
            if not active:  # the hull pre-test's pairs (robots.collision_hulls)
                gd.deactivateCollisionPair(k)
    return pool


class BatchEdgeChecker:
    """Checks lists of straight motions (joint limits and collisions) in one call.

    ``threads``: Pinocchio worker threads (default: the cores this process may use).
    """

    def __init__(self, checker: MotionChecker, threads: int | None = None) -> None:
        self.checker = checker
        self.threads = threads or max(len(os.sched_getaffinity(0)), 1)
        self.pool = _pool(checker.arm, self.threads)
        self.checks = 0

    def _counts(self, A: NDArray[np.float64], B: NDArray[np.float64]) -> NDArray[np.int64]:
        """Steps per motion so that no joint moves more than the joint step and the TCP no
        more than the TCP step between samples (all motions at once, batched D-H FK)."""
        c = self.checker
        n = np.maximum(np.ceil(np.abs(B - A).max(axis=1) / c.joint_step), 1).astype(np.int64)
        todo = np.arange(len(A))
        for _ in range(8):
            if not len(todo):
                break
            reps = n[todo] + 1
            t = np.concatenate([np.linspace(0.0, 1.0, r) for r in reps])[:, None]
            idx = np.repeat(todo, reps)
            Q = A[idx] + t * (B[idx] - A[idx])
            tcp = c.arm.fk_dh(Q, "tcp")[:, :3, 3]
            step = np.linalg.norm(np.diff(tcp, axis=0), axis=1)
            step[np.cumsum(reps)[:-1] - 1] = 0.0  # no step across two motions
            worst = np.maximum.reduceat(
                np.append(step, 0.0), np.concatenate([[0], np.cumsum(reps)[:-1]])
            )
            bad = worst > c.tcp_step
            n[todo[bad]] = np.ceil(n[todo[bad]] * worst[bad] / c.tcp_step * 1.05).astype(np.int64)
            todo = todo[bad]
        return n

    @staticmethod
    def _trajectory(q_a: NDArray[np.float64], q_b: NDArray[np.float64], n: int) -> NDArray:
        """The ``n + 1`` samples of the motion, interior coarse to fine, then both ends."""
        t = np.linspace(0.0, 1.0, n + 1)[:, None]
        Q = q_a + t * (q_b - q_a)
        inner = _interpolation_order(n)
        return Q[np.concatenate([inner, [0, n]])] if len(inner) else Q

    def free(self, starts: NDArray[np.float64], ends: NDArray[np.float64]) -> NDArray[np.bool_]:
        """For each row pair (``starts[i]`` → ``ends[i]``, rad): True when the straight motion
        is within the limits and free of collision at the checker's resolution."""
        A, B = np.asarray(starts, dtype=float), np.asarray(ends, dtype=float)
        if not len(A):
            return np.zeros(0, dtype=bool)
        counts = self._counts(A, B)
        trajs = [self._trajectory(a, b, int(n)) for a, b, n in zip(A, B, counts, strict=True)]
        inside = np.array([self.checker._inside(Q) for Q in trajs], dtype=bool)
        out = np.zeros(len(trajs), dtype=bool)
        todo = np.flatnonzero(inside)
        if not len(todo):
            return out
        # the motions share their ends (each node is the end of many): every distinct end
        # configuration is checked once, each motion's interior samples in its own trajectory
        ends, which = np.unique(np.vstack([A[todo], B[todo]]), axis=0, return_inverse=True)
        which = which.reshape(2, len(todo))
        inner = [trajs[i][:-2] for i in todo]  # the ends are the last two rows
        self.checks += len(ends) + int(sum(len(Q) for Q in inner))
        end_free = ~self._hits([e[None, :] for e in ends])
        inner_free = ~self._hits(inner)
        out[todo] = end_free[which[0]] & end_free[which[1]] & inner_free
        return out

    def _hits(self, trajs: list[NDArray[np.float64]]) -> NDArray[np.bool_]:
        """For each trajectory (rows: configurations): True when one of them collides."""
        hit = np.zeros(len(trajs), dtype=bool)
        some = [i for i, Q in enumerate(trajs) if len(Q)]
        if not some:
            return hit
        if self.pool is None:
            arm = self.checker.arm
            hit[some] = [any(arm.in_collision(q) for q in trajs[i]) for i in some]
            return hit
        batch: Sequence[NDArray] = [np.asfortranarray(trajs[i].T) for i in some]
        res = pin.computeCollisionsInParallel(self.threads, self.pool, list(batch), True)
        hit[some] = [np.asarray(h).any() for h in res]
        return hit
