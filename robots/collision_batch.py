"""Many collision checks in one call: Pinocchio's ``computeCollisionsInParallel``.

:class:`BatchCollision` keeps a pool of broad-phase managers (coal's dynamic AABB tree)
over an arm's :class:`~robots.collision.CollisionModel`, with the requests set up as the
model's own exact pairs (contacts on, GJK from the default guess, the clearance margins;
the convex-hull pre-test's pairs switched off), so each answer equals
``CollisionModel.in_collision`` at the same configuration. One call checks a batch of
configurations (:meth:`each`) or of trajectories, each stopped at its first collision
(:meth:`any_hit`); the loop over configurations runs in C++, not Python.

Below ``PARALLEL_MIN_CONFIGS`` configurations a batch is checked one configuration at a
time by the model's own :meth:`~robots.collision.CollisionModel.in_collision` instead
(its naive broad phase and, for mesh arms, the hull pre-test): measured on the built-in
frame cell, idle machine, 40 000 configurations near home, 10.7 us per configuration
against 18.2 us for the pool on one thread (9.5 us wall, 18.6 us CPU on two). Which path
answers depends on the batch's size only, never on the thread count, so a start's tour
does not depend on the cores of the machine that planned it.
"""

from __future__ import annotations

import os
from typing import Any

import coal
import numpy as np
import pinocchio as pin
from numpy.typing import NDArray

#: batches of fewer configurations than this are checked one at a time (module docstring),
#: not by the pool on one thread, nor on two: OpenMP's start and its
#: spinning workers cost more CPU than a small batch saves (measured on cluttered-80 at
#: load 3.3-3.6: batches of 2000-50 000 configurations, 5-20 % more CPU on two threads and
#: no shorter wall time; 60 lazy-round batches of 8 motions: 0.7-0.8 s CPU on one thread,
#: 1.5 s on two). Large batches (a roadmap, ~10^5 configurations) still use every core: on an
#: idle machine, with nothing else running, that is where two threads can halve the wall.
PARALLEL_MIN_CONFIGS = 20000


def default_threads() -> int:
    """Worker threads: the cores this process may use."""
    return max(len(os.sched_getaffinity(0)), 1)


class BatchCollision:
    """Batch checks against a collision model (``model``, ``geom_model``, ``geom_data``).

    ``threads``: worker threads for large batches (default: the cores this process may use).
    """

    def __init__(self, collision: Any, threads: int | None = None) -> None:
        self.collision = collision
        self.threads = threads or default_threads()
        self.pool = pin.BroadPhaseManagerPool_DynamicAABBTreeCollisionManager(
            collision.model, collision.geom_model, self.threads
        )
        # the same requests as the arm's own checks, clearance margins included
        margins = [req.security_margin for req in collision.geom_data.collisionRequests]
        for gd in self.pool.getGeometryDatas():
            for req, margin in zip(gd.collisionRequests, margins, strict=True):
                req.enable_contact = True
                req.gjk_initial_guess = coal.GJKInitialGuess.DefaultGuess
                req.security_margin = margin
            for k, active in enumerate(collision.geom_data.activeCollisionPairs):
                if not active:  # the hull pre-test's pairs (robots.collision_hulls)
                    gd.deactivateCollisionPair(k)

    @classmethod
    def of_arm(cls, arm: object, threads: int | None = None) -> BatchCollision | None:
        """The batch checker of ``arm``'s collision model (None: no Pinocchio model)."""
        collision = getattr(arm, "collision", None)
        if collision is None or not hasattr(collision, "geom_model"):
            return None
        return cls(collision, threads)

    def each(self, Q: NDArray[np.float64]) -> NDArray[np.bool_]:
        """For each configuration (rows of ``Q``, (N, nq) rad): True when in collision."""
        Q = np.asarray(Q, dtype=float)
        if not len(Q):
            return np.zeros(0, dtype=bool)
        if len(Q) < PARALLEL_MIN_CONFIGS:
            Q = np.ascontiguousarray(Q)
            hit = self.collision.in_collision
            return np.fromiter((hit(q) for q in Q), dtype=bool, count=len(Q))
        res = pin.computeCollisionsInParallel(self.threads, self.pool, np.asfortranarray(Q.T), True)
        return np.asarray(res, dtype=bool).reshape(len(Q))

    def any_hit(self, trajs: list[NDArray[np.float64]]) -> NDArray[np.bool_]:
        """For each trajectory ((nq, m) rad, columns in checking order): True when one of
        its configurations collides (each trajectory stops at its first collision)."""
        hit = np.zeros(len(trajs), dtype=bool)
        some = [i for i, Q in enumerate(trajs) if Q.shape[1]]
        if not some:
            return hit
        size = sum(trajs[i].shape[1] for i in some)
        if size < PARALLEL_MIN_CONFIGS:
            check = self.collision.in_collision
            for i in some:
                rows = np.ascontiguousarray(np.asarray(trajs[i], dtype=float).T)
                hit[i] = any(check(q) for q in rows)
            return hit
        batch = [np.asfortranarray(trajs[i]) for i in some]
        res = pin.computeCollisionsInParallel(self.threads, self.pool, batch, True)
        hit[some] = [np.asarray(h).any() for h in res]
        return hit
