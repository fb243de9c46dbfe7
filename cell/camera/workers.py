"""Where the pairs of a tour are rendered and detected: worker processes, or this process.

A tour's views (the calibration's, the survey's) are detected while the arm moves on. A camera
that can take a snapshot (the simulated head: ``snapshot()`` returns a picklable function that
renders the pair it saw) has its pairs rendered in the workers too, so the arm never waits for a
render. :func:`executor` gives the workers (one pool per process, kept from tour to tour, so
their start-up and the renderer's per-camera caches are paid once); :func:`pair_source` what
one capture hands them. :func:`start_workers` starts them ahead of the first tour, each warming
itself (a camera's renderer and detector) while this process still plans.

Each worker runs its libraries single-threaded (OpenCV, BLAS): the workers are as many as the
cores, and threads inside them would only compete for the same cores.
"""

from __future__ import annotations

import logging
import multiprocessing
import threading
from collections.abc import Callable
from concurrent import futures
from concurrent.futures import Executor, Future, ProcessPoolExecutor
from typing import Any

from cell.camera.backend import StereoPair

#: what a capture hands to a worker: the pair, or a function that renders it
PairSource = StereoPair | Callable[[], StereoPair]

#: captured pairs (5 MP each) that may wait for a worker before the arm waits for them
PAIRS_WAITING_PER_WORKER = 2


class InProcess(Executor):
    """Runs each job at once, in this process (``workers=0``)."""

    def submit(self, fn, /, *args, **kwargs) -> Future:  # type: ignore[override]
        future: Future = Future()
        try:
            future.set_result(fn(*args, **kwargs))
        except Exception as exc:  # handed to the caller by result()
            future.set_exception(exc)
        return future


class Shared(Executor):
    """One user's view of the process's shared pool: :meth:`shutdown` cancels (and with
    ``wait`` awaits) the jobs submitted through it, and leaves the workers running for the
    next user (their imports and the renderer's per-camera caches are paid once)."""

    def __init__(self, pool: ProcessPoolExecutor) -> None:
        self._pool = pool
        self._jobs: list[Future] = []

    def submit(self, fn, /, *args, **kwargs) -> Future:  # type: ignore[override]
        self._jobs = [f for f in self._jobs if not f.done()]
        future = self._pool.submit(fn, *args, **kwargs)
        self._jobs.append(future)
        return future

    def shutdown(self, wait: bool = True, *, cancel_futures: bool = False) -> None:
        if cancel_futures:
            for f in self._jobs:
                f.cancel()
        if wait:
            futures.wait(self._jobs)
        self._jobs = []


#: the process's worker pools by size, started on first use and kept until the process ends
_POOLS: dict[int, ProcessPoolExecutor] = {}
_POOLS_LOCK = threading.Lock()

log = logging.getLogger(__name__)


def executor(workers: int) -> Executor:
    """``workers`` processes started by a fork server (a process that runs a simulator holds
    threads whose locks a forked child would inherit locked), shared by the tours of this
    process (:class:`Shared`; a pool whose worker died is started again), or this process."""
    if workers <= 0:
        return InProcess()
    return Shared(_pool(workers, None))


def start_workers(workers: int, warm: Callable[[], Any] | None = None) -> bool:
    """Start the pool of ``workers`` processes now (no-op for 0, or when it runs already), each
    process calling ``warm`` (picklable; its errors are logged, not raised) before its first
    job; returns whether this call started it. The tours that follow use these workers
    (:func:`executor`)."""
    if workers <= 0:
        return False
    with _POOLS_LOCK:
        pool = _POOLS.get(workers)
        if pool is not None and not getattr(pool, "_broken", False):
            return False
    pool = _pool(workers, warm)
    for _ in range(workers):  # a fork server's pool starts one process per job waiting
        pool.submit(int)
    return True


def _pool(workers: int, warm: Callable[[], Any] | None) -> ProcessPoolExecutor:
    """The process's pool of ``workers`` (started, with ``warm``, when missing or broken)."""
    with _POOLS_LOCK:
        pool = _POOLS.get(workers)
        if pool is None or getattr(pool, "_broken", False):
            ctx = multiprocessing.get_context("forkserver")
            pool = _POOLS[workers] = ProcessPoolExecutor(
                max_workers=workers, mp_context=ctx, initializer=_worker_start, initargs=(warm,)
            )
        return pool


def _worker_start(warm: Callable[[], Any] | None) -> None:
    """A worker's start: its libraries single-threaded, then ``warm``."""
    import cv2
    from threadpoolctl import threadpool_limits

    cv2.setNumThreads(1)
    threadpool_limits(1)
    if warm is None:
        return
    try:
        warm()
    except Exception as exc:  # a cold worker still works: say so, do not break the pool
        log.warning("a worker's warm-up failed (%s: %s)", type(exc).__name__, exc)


def pair_source(camera: Any) -> tuple[PairSource, bool]:
    """One capture for a worker: the camera's snapshot when it can take one, else its pair; and
    whether it is a pair (pairs wait in memory: the arm waits when too many do)."""
    snapshot = getattr(camera, "snapshot", None)
    if snapshot is not None:
        return snapshot(), False
    return camera.capture(), True


def rendered(source: PairSource) -> tuple[StereoPair, bool]:
    """The pair of a source, and whether it was rendered here (a snapshot)."""
    if isinstance(source, StereoPair):
        return source, False
    return source(), True
