"""Lazy collision checks of the tour's motions: the rounds between sequencing and paths.

The roadmap (:mod:`planner.roadmap`) checks each candidate node's near motions up front;
every other motion is assumed free until a tour uses it. A round checks, in one batch,

- at the roadmap's coarse resolution (it proves collisions at a sixth of the cost), the
  unknown motions of the tour and of every tour the search accepted on its way there;
- for each colliding tour motion, its *siblings*: the ``SIBLINGS`` cheapest unknown
  motions between the same two holes by other candidates that look cheaper than its
  detour (the next search would otherwise try them one at a time); in a cluttered round
  (at least ``CLUTTERED_HITS`` colliding tour motions), while all of a batch collide, the
  next twice as many, probed ``PROBE_COARSENESS`` times coarser than the set resolution
  (a colliding probe sample proves the collision; a free probe proves nothing);
- above ``NEAR_ABOVE`` holes, in a cluttered round, each colliding tour motion's
  *corridor* (``CORRIDOR``), probed;

every colliding motion gets its roadmap detour cost, and a short repair search
re-sequences from the tour. When the tour has no colliding motion left, its unknown
motions are checked at the set resolution (a collision there: another round).

Work limits, not clocks: at most ``LAZY_ROUNDS`` rounds per call (above ``NEAR_ABOVE``
holes, ``2 × LAZY_ROUNDS × NEAR_ABOVE / holes`` per start, all calls together); the time cap
``LAZY_BUDGET_SHARE`` × the sequencing budget (thread CPU time) only binds on a crawling
machine (at 3× it bound on cluttered-80 and the same seed gave different tours).
"""

from __future__ import annotations

import itertools
import time
from collections.abc import Iterator

import numpy as np
from numpy.typing import NDArray

from planner.edge_check import BatchEdgeChecker
from planner.lns import NEAR_ABOVE
from planner.options import Options
from planner.paths import MotionChecker
from planner.roadmap import Roadmap, detour_costs
from planner.sequence import GtspSequencer, SequenceResult

#: time cap of each repair search after costs changed, as a share of the sequencing budget
REFINE_SHARE = 0.15
#: at most this many lazy re-sequencing rounds per call, up to ``NEAR_ABOVE`` holes; above,
#: a share ``NEAR_ABOVE / holes`` of it for the whole start, all calls together (each
#: round's repair grows with the holes, and at 250 holes the rounds wander without
#: converging: the tour after 30 rounds was as short as after 60) ...
LAZY_ROUNDS = 60
#: ... and a safety cap in time, as a multiple of the sequencing budget
LAZY_BUDGET_SHARE = 20.0
#: a colliding tour motion: this many of the cheapest unknown motions between the same two
#: holes (other candidates) are checked with it
SIBLINGS = 8
#: ... and when a round's tour had at least this many colliding motions (a cluttered cell),
#: while all of a batch collide, twice as many more (probed, see PROBE_COARSENESS)
CLUTTERED_HITS = 4
#: probes are this many times coarser than the set resolution (a handful of samples per
#: motion: a colliding one proves the collision, a free one proves nothing)
PROBE_COARSENESS = 48.0
#: above ``NEAR_ABOVE`` holes, in a cluttered round, each colliding tour motion between
#: holes A and B also probes the motions of its *corridor*: between A or one of its
#: ``CORRIDOR`` nearest holes and B or one of B's (the next search moves a blocked jump to
#: the neighbouring holes, behind the same obstacle: at 250 holes, 65 % of the colliding
#: tour motions joined holes within 3 of an earlier one's), the ``SIBLINGS`` cheapest
#: unknown ones per hole pair that look cheaper than the detour
CORRIDOR = 3


def _distinct(pairs: NDArray[np.int64], n_nodes: int) -> NDArray[np.int64]:
    """The distinct rows of a (m, 2) array of node pairs, in sorted order."""
    code = np.unique(pairs.astype(np.int64) @ np.array([n_nodes, 1]))
    return np.column_stack([code // n_nodes, code % n_nodes])


def _cheaper_motions(
    seqr: GtspSequencer, a: int, b: int, below_s: float
) -> Iterator[tuple[int, int]]:
    """The motions between the nodes of groups ``a`` and ``b`` (0: home, h + 1: hole h) that
    cost less than ``below_s`` (s), cheapest first (ties: row-major), as (min, max) pairs."""
    ga, gb = (np.array([0]) if g == 0 else seqr.groups[g - 1] for g in (a, b))
    C = seqr.G[np.ix_(ga, gb)]
    order = np.argsort(C, axis=None, kind="stable")
    for f in order[C.ravel()[order] < below_s].tolist():
        i, j = divmod(f, len(gb))
        x, y = int(ga[i]), int(gb[j])
        yield (min(x, y), max(x, y))


class LazyEdgeChecks:
    """The lazy rounds of :class:`planner.planner.TourPlanner` (state set up per start by
    its ``_sequence_and_paths``: the roadmap, the known motions, the batch checkers)."""

    options: Options
    _roadmap: Roadmap
    _edge_free: dict[tuple[int, int], bool]
    _coarse_free: set[tuple[int, int]]
    _batch: BatchEdgeChecker
    _coarse_batch: BatchEdgeChecker
    _probe_batch: BatchEdgeChecker
    _lazy_rounds: int
    _siblings: int
    _corridor: int

    def _avoid_colliding_edges(
        self,
        seqr: GtspSequencer,
        res: SequenceResult,
        checker: MotionChecker,
        n_holes: int,
        seen: list[list[int]],
    ) -> SequenceResult:
        """Lazy rounds (module docstring) until the tour's motions are known to be free;
        ``seen``: the tours the search accepted on its way to ``res``."""
        o = self.options
        started = time.thread_time()
        rounds = LAZY_ROUNDS
        if n_holes > NEAR_ABOVE:
            rounds = max(0, 2 * LAZY_ROUNDS * NEAR_ABOVE // n_holes - self._lazy_rounds)
        for k in range(rounds + 1):
            on_tour = self._blocked_on_tours(seqr, res.nodes or [], seen, checker)
            out_of_work = k == rounds
            out_of_time = time.thread_time() - started > LAZY_BUDGET_SHARE * o.budget_s(n_holes)
            if not on_tour or out_of_work or out_of_time:
                break
            budget = o.budget_s(n_holes) * REFINE_SHARE
            seen = []
            res = seqr.solve(budget, o.seed + 100 + k, o.effort, res.nodes, True, seen)
        self._lazy_rounds += k
        return res

    def _blocked_on_tours(
        self,
        seqr: GtspSequencer,
        nodes: list[int],
        seen: list[list[int]],
        checker: MotionChecker,
    ) -> bool:
        """Check the unknown motions of the tour ``nodes`` and of the ``seen`` tours (see
        :meth:`_avoid_colliding_edges`), learn the detour cost of every colliding one; True
        when the tour itself had a colliding motion whose cost was not a detour's yet."""
        tours = [np.array([0, *t, 0]) for t in (nodes, *seen)]
        N = len(seqr.nodes)
        arcs = _distinct(np.concatenate([np.column_stack([t[:-1], t[1:]]) for t in tours]), N)
        keys = _distinct(np.sort(arcs, axis=1), N)  # the motions as (min, max)
        todo = [k for k in map(tuple, keys.tolist()) if k not in self._edge_free]
        todo = [k for k in todo if k not in self._coarse_free]
        if todo:
            free = self._free(self._coarse_batch, seqr, todo, checker)
            for key, f in zip(todo, free.tolist(), strict=True):
                if f:
                    self._coarse_free.add(key)
                else:
                    self._edge_free[key] = False
        path = tours[0].tolist()
        fine = sorted({(min(u, v), max(u, v)) for u, v in itertools.pairwise(path)})
        if not any(self._edge_free.get(key) is False for key in fine):
            todo = [key for key in fine if key not in self._edge_free]
            if todo:
                free = self._free(self._batch, seqr, todo, checker)
                self._edge_free.update(zip(todo, free.tolist(), strict=True))
        blocked = [
            (u, v)
            for u, v in map(tuple, arcs.tolist())
            if self._edge_free.get((min(u, v), max(u, v))) is False and (u, v) not in seqr.learned
        ]
        on_tour = set(itertools.pairwise(path))
        if blocked:
            seqr.learn(detour_costs(self._roadmap, seqr.G, blocked))
        hit = [e for e in blocked if e in on_tour]
        if hit:
            self._block_siblings(seqr, hit, checker)
        if len(hit) >= CLUTTERED_HITS and len(seqr.groups) > NEAR_ABOVE:
            self._block_corridors(seqr, hit, checker)
        return bool(hit)

    def _block_corridors(
        self, seqr: GtspSequencer, hit: list[tuple[int, int]], checker: MotionChecker
    ) -> None:
        """Probe the corridor of each colliding tour motion (see ``CORRIDOR``) in one batch;
        the colliding probes are learned (a free probe proves nothing)."""
        near = seqr.near_holes()[:, :CORRIDOR]
        keys: set[tuple[int, int]] = set()
        for u, v in hit:
            a, b = int(seqr.owner[u]) + 1, int(seqr.owner[v]) + 1
            if a == 0 or b == 0:
                continue
            ends_a = [a, *(near[a - 1] + 1).tolist()]  # group indices: hole h is h + 1
            ends_b = [b, *(near[b - 1] + 1).tolist()]
            for a2, b2 in itertools.product(ends_a, ends_b):
                if a2 == b2 or (a2, b2) == (a, b) or (a2, b2) == (b, a):
                    continue
                found = 0
                for key in _cheaper_motions(seqr, a2, b2, seqr.G[u, v]):
                    if key in self._edge_free or key in self._coarse_free or key in keys:
                        continue
                    keys.add(key)
                    found += 1
                    if found == SIBLINGS:
                        break
        todo = sorted(keys)
        if not todo:
            return
        free = self._free(self._probe_batch, seqr, todo, checker)
        blocked = [k for k, f in zip(todo, free.tolist(), strict=True) if not f]
        for k in blocked:
            self._edge_free[k] = False
        self._corridor += len(blocked)
        if blocked:
            seqr.learn(detour_costs(self._roadmap, seqr.G, blocked))

    def _block_siblings(
        self, seqr: GtspSequencer, hit: list[tuple[int, int]], checker: MotionChecker
    ) -> None:
        """The motions between the same two holes as a colliding tour motion, by other
        candidates, that look cheaper than its detour: the ``SIBLINGS`` cheapest unknown ones
        checked coarse in one batch, the colliding ones learned (the next search would try
        them one by one); while all of a batch collide (an obstacle between the two holes),
        the next twice as many."""
        queue = {}
        for u, v in hit:
            a, b = int(seqr.owner[u]) + 1, int(seqr.owner[v]) + 1
            motions = _cheaper_motions(seqr, a, b, seqr.G[u, v])
            queue[(u, v)] = [k for k in motions if k not in self._edge_free]
        size = SIBLINGS
        grow = len(hit) >= CLUTTERED_HITS
        while queue and (grow or size == SIBLINGS):
            batches = {}
            for e, keys in queue.items():
                todo = [k for k in keys if k not in self._edge_free and k not in self._coarse_free]
                batches[e], queue[e] = todo[:size], todo[size:]
            keys = sorted({k for ks in batches.values() for k in ks})
            if not keys:
                return
            batch = self._coarse_batch if size == SIBLINGS else self._probe_batch
            free = dict(zip(keys, self._free(batch, seqr, keys, checker), strict=True))
            blocked = [k for k in keys if not free[k]]
            for k in keys:
                if not free[k]:
                    self._edge_free[k] = False
                elif batch is self._coarse_batch:  # a probe's "free" proves nothing
                    self._coarse_free.add(k)
            self._siblings += len(blocked)
            if blocked:
                seqr.learn(detour_costs(self._roadmap, seqr.G, blocked))
            queue = {
                e: rest
                for e, rest in queue.items()
                if rest and batches[e] and not any(free[k] for k in batches[e])
            }
            size *= 2

    @staticmethod
    def _free(
        batch: BatchEdgeChecker,
        seqr: GtspSequencer,
        keys: list[tuple[int, int]],
        checker: MotionChecker,
    ) -> NDArray[np.bool_]:
        e = np.array(keys)
        free = batch.free(seqr.nodes[e[:, 0]], seqr.nodes[e[:, 1]])
        checker.checks += batch.checks
        batch.checks = 0
        return free
