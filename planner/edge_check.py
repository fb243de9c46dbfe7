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
    for gd in pool.getGeometryDatas():
        for req in gd.collisionRequests:
            req.enable_contact = True
            req.gjk_initial_guess = coal.GJKInitialGuess.DefaultGuess
            req.security_margin = 0.0
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

    def _trajectory(self, q_a: NDArray[np.float64], q_b: NDArray[np.float64]) -> NDArray:
        Q = self.checker.samples(q_a, q_b)
        inner = _interpolation_order(len(Q) - 1)
        return Q[np.concatenate([inner, [0, len(Q) - 1]])] if len(inner) else Q

    def free(self, starts: NDArray[np.float64], ends: NDArray[np.float64]) -> NDArray[np.bool_]:
        """For each row pair (``starts[i]`` → ``ends[i]``, rad): True when the straight motion
        is within the limits and free of collision at the checker's resolution."""
        trajs = [self._trajectory(a, b) for a, b in zip(starts, ends, strict=True)]
        inside = np.array([self.checker._inside(Q) for Q in trajs], dtype=bool)
        out = np.zeros(len(trajs), dtype=bool)
        todo = np.flatnonzero(inside)
        if not len(todo):
            return out
        self.checks += int(sum(len(trajs[i]) for i in todo))
        if self.pool is None:
            arm = self.checker.arm
            out[todo] = [not any(arm.in_collision(q) for q in trajs[i]) for i in todo]
            return out
        batch: Sequence[NDArray] = [np.asfortranarray(trajs[i].T) for i in todo]
        hits = pin.computeCollisionsInParallel(self.threads, self.pool, list(batch), True)
        out[todo] = [not np.asarray(h).any() for h in hits]
        return out
