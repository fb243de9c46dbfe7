"""A helper process on the second core for the seed-independent stages.

The viewpoints (IK and collision checks per hole, in Python) and the roadmap's batch of
motion checks are independent per hole and per motion. While :meth:`TourPlanner.prepare`
computes them, a :class:`Helper` — one process forked from this one, so it starts at once
with the arm already built — takes a share: chunks of holes from the back of the list
while this process works from the front (:func:`planner.viewpoints.all_hole_candidates`),
and chunks of the roadmap's motions the same way (:meth:`planner.edge_check.BatchEdgeChecker.free`),
each process checking one configuration per call. Every answer is a function of its hole or
motion alone, so the results, the tour and the collision-check counts are the same with
or without the helper, whichever process computed what.

The helper runs only where it can pay: at least ``MIN_HOLES`` holes, two cores this
process may use, ``fork`` available, and not inside a daemonic worker (which may not have
children). Otherwise everything runs here as before.
"""

from __future__ import annotations

import logging
import multiprocessing
import time
from collections.abc import Callable
from concurrent.futures import BrokenExecutor, Future, ProcessPoolExecutor
from typing import Any

from planner.protocols import ArmLike

log = logging.getLogger(__name__)

#: the helper starts for cells of at least this many holes (below, the fork and the
#: pickling cost about what the second core saves)
MIN_HOLES = 40

#: what the forked helper inherits: set just before the fork, read by the helper's tasks
_STATE: dict[str, Any] = {}


def _cores() -> int:
    import os

    return len(os.sched_getaffinity(0))


def helper_arm() -> ArmLike:
    """The arm of the process that forked this helper (in the helper process)."""
    return _STATE["arm"]


class Helper:
    """One forked process that runs submitted top-level functions, in submission order."""

    def __init__(self, pool: ProcessPoolExecutor) -> None:
        self.pool = pool

    @staticmethod
    def can_pay(size: int) -> bool:
        """True where a helper would start for a cell of ``size`` holes (module docstring)."""
        return (
            size >= MIN_HOLES
            and _cores() >= 2
            and not multiprocessing.current_process().daemon
            and "fork" in multiprocessing.get_all_start_methods()
        )

    @classmethod
    def start(cls, size: int, **state: Any) -> Helper | None:
        """A helper that inherits ``state`` (e.g. ``arm=``) for a cell of ``size`` holes, or None
        where it cannot pay (:meth:`can_pay`) or no process can be made."""
        if not cls.can_pay(size):
            return None
        _STATE.clear()
        _STATE.update(state)
        try:
            pool = ProcessPoolExecutor(1, mp_context=multiprocessing.get_context("fork"))
            pool.submit(int).result()  # forks now, with the state above
        except (OSError, RuntimeError) as exc:  # no process for us: everything runs here
            log.info("no helper process (%s); one core", exc)
            return None
        finally:
            _STATE.clear()  # the parent keeps no reference to the arm
        return cls(pool)

    def submit(self, fn: Callable[..., Any], *args: Any) -> Future[Any]:
        """Run ``fn(*args)`` in the helper (after everything submitted before); a helper
        that died gives a future holding :class:`BrokenExecutor` (see :meth:`result`)."""
        try:
            return self.pool.submit(fn, *args)
        except (BrokenExecutor, RuntimeError) as exc:
            failed: Future[Any] = Future()
            failed.set_exception(BrokenExecutor(str(exc)))
            return failed

    @staticmethod
    def result(future: Future[Any], fallback: Callable[[], Any]) -> Any:
        """The result of ``future``, or ``fallback()`` here when the helper process died."""
        try:
            return future.result()
        except BrokenExecutor as exc:
            log.warning("the helper process stopped (%s); its share runs here", exc)
            return fallback()

    def close(self) -> float:
        """Stop the helper (pending work is cancelled); returns the CPU time (s) it used."""
        try:
            cpu = float(self.pool.submit(time.process_time).result())
        except (BrokenExecutor, OSError):  # a helper that died: its time is unknown
            cpu = 0.0
        self.pool.shutdown(wait=False, cancel_futures=True)
        return cpu

    def __enter__(self) -> Helper:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
