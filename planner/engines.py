"""Engines that run independent planning starts: local processes, or a Ray cluster.

An engine maps a picklable top-level function over a list of argument tuples and
returns the results in the order of the arguments; ``shared`` (optional) is appended to
every call's arguments and shipped once where the engine can (Ray: one object in the
object store; local processes: the same bytes to each worker). Every call runs in a fresh
process (local: a ``forkserver`` pool with one task per child; Ray: a task whose
worker exits after it, ``max_calls=1``), because OMPL's random generator can be
seeded only once per process: a start's result then depends on its seed alone,
not on which worker ran it or what ran there before.
"""

from __future__ import annotations

import multiprocessing
import multiprocessing.forkserver
import os
from collections.abc import Callable, Sequence
from concurrent.futures import ProcessPoolExecutor
from typing import Any, Protocol

from planner.errors import EngineError


class Engine(Protocol):
    """Runs ``fn(*args)`` (``fn(*args, shared)`` when given) for each tuple of ``calls``;
    results in order."""

    name: str

    def map(
        self, fn: Callable[..., Any], calls: Sequence[tuple], shared: Any = None
    ) -> list[Any]: ...


def local_cores() -> int:
    """Cores this process may run on."""
    return max(len(os.sched_getaffinity(0)), 1)


class LocalEngine:
    """Independent processes on this machine, ``jobs`` at a time (default: every core)."""

    def __init__(self, jobs: int | None = None) -> None:
        if jobs is not None and jobs < 1:
            raise EngineError("local", f"jobs must be at least 1, got {jobs}")
        self.jobs = jobs or local_cores()
        self.name = f"local ({self.jobs} processes)"
        self.preload = ["planner.planner"]

    def warm_up(self, modules: Sequence[str] = ()) -> None:
        """Start the fork server now, preloading the planner and ``modules`` (e.g. the cell's),
        so that it imports them while this process computes the shared part; the workers,
        forked from it, then start with every import done."""
        extra = [m for m in modules if m and m != "__main__"]
        self.preload = list(dict.fromkeys([*self.preload, *extra]))
        multiprocessing.get_context("forkserver").set_forkserver_preload(self.preload)
        multiprocessing.forkserver.ensure_running()

    def map(self, fn: Callable[..., Any], calls: Sequence[tuple], shared: Any = None) -> list[Any]:
        if not calls:
            return []
        ctx = multiprocessing.get_context("forkserver")
        ctx.set_forkserver_preload(self.preload)  # no effect once the server runs
        tail = () if shared is None else (shared,)
        workers = min(self.jobs, len(calls))
        with ProcessPoolExecutor(workers, mp_context=ctx, max_tasks_per_child=1) as pool:
            futures = [pool.submit(fn, *args, *tail) for args in calls]
            return [f.result() for f in futures]


class RayEngine:
    """Tasks on a Ray cluster at ``address`` (``"local"``: start a local Ray instance)."""

    def __init__(self, address: str, num_cpus: int | None = None) -> None:
        try:
            import ray
        except ImportError as exc:
            raise EngineError(
                "--ray", "Ray is not installed; install it with: pip install 'holecell[ray]'"
            ) from exc
        self.ray = ray
        self.name = f"ray ({address})"
        if not ray.is_initialized():
            kwargs: dict[str, Any] = {"include_dashboard": False, "log_to_driver": False}
            try:
                if address == "local":
                    ray.init(num_cpus=num_cpus or local_cores(), **kwargs)
                else:
                    ray.init(address=address, **kwargs)
            except (ConnectionError, RuntimeError, ValueError) as exc:
                raise EngineError("--ray", f"cannot connect to Ray at {address}: {exc}") from exc

    def map(self, fn: Callable[..., Any], calls: Sequence[tuple], shared: Any = None) -> list[Any]:
        task = self.ray.remote(max_calls=1, num_cpus=1)(fn)
        tail = () if shared is None else (self.ray.put(shared),)  # stored once
        return self.ray.get([task.remote(*args, *tail) for args in calls])


def make_engine(ray_address: str | None = None, jobs: int | None = None) -> Engine:
    """The Ray engine when an address is given, else local processes."""
    return RayEngine(ray_address) if ray_address else LocalEngine(jobs)
