"""Where the pairs of a tour are rendered and detected: worker processes, or this process.

A tour's views (the calibration's, the survey's) are detected while the arm moves on. A camera
that can take a snapshot (the simulated head: ``snapshot()`` returns a picklable function that
renders the pair it saw) has its pairs rendered in the workers too, so the arm never waits for a
render. :func:`executor` gives the workers; :func:`pair_source` what one capture hands them.
"""

from __future__ import annotations

import multiprocessing
from collections.abc import Callable
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


def executor(workers: int) -> Executor:
    """``workers`` processes started by a fork server (a process that runs a simulator holds
    threads whose locks a forked child would inherit locked), or this process."""
    if workers <= 0:
        return InProcess()
    ctx = multiprocessing.get_context("forkserver")
    return ProcessPoolExecutor(max_workers=workers, mp_context=ctx)


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
