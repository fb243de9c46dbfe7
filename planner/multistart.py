"""Multi-start planning: independent starts (seeds) on an engine, the best tour kept.

The seed-independent part (viewpoints, the GTSP's nodes and costs, the roadmap;
:mod:`planner.shared`) is computed once, in this process, while the engine's workers
start up; start ``k`` of ``starts`` then runs the seed-dependent stages (sequence, lazy
rounds, paths, timing) on its own copy with seed ``options.seed × starts + k``, so the
sets of start seeds of two base seeds never overlap. Each start is deterministic for
its seed (work limits, not clocks; see :mod:`planner.sequence`), gives the same tour
with or without the shared part handed to it, and runs in a fresh process, so the best
tour — the shortest cycle time, ties to the lowest seed — is the same whichever engine
(:mod:`planner.engines`) ran the starts.
"""

from __future__ import annotations

import dataclasses
import gc
import logging
import time

from planner.engines import Engine, LocalEngine
from planner.errors import PlanningError, StartsFailedError
from planner.lns import COMPILED_ABOVE
from planner.options import Options
from planner.planner import TourPlanner
from planner.protocols import CellLike
from planner.shared import pack
from planner.tour import Tour

#: independent starts of ``holecell plan`` (fixed, so the tour does not depend on the machine)
DEFAULT_STARTS = 2


def start_seeds(options: Options, starts: int) -> list[int]:
    """Seeds of the independent starts of ``options.seed``."""
    return [options.seed * starts + k for k in range(starts)]


def plan_one(cell: CellLike, options: Options, shared: bytes | None = None) -> Tour | str:
    """One start (runs in a worker): the tour (``settings["cpu_time_s"]``: the CPU time of
    the start, every thread; with ``shared`` (:func:`planner.shared.pack`) the start's own
    part only), or the planning error's message."""
    # the summary lists holes left out once; the starts need not warn about them each
    logging.getLogger("planner").setLevel(logging.ERROR)
    cpu = time.process_time()
    try:
        tour = TourPlanner(options).plan(cell, shared)
        tour.settings["cpu_time_s"] = time.process_time() - cpu
    except PlanningError as exc:
        return f"{type(exc).__name__}: {exc}"
    finally:
        gc.collect()  # free the OMPL objects before the worker exits
    return tour


def best_tour(results: list[Tour | str], seeds: list[int]) -> Tour:
    """The tour with the shortest cycle time (ties: lowest seed); every start failed → error."""
    tours = [
        (r.cycle_time_s, s, r) for r, s in zip(results, seeds, strict=True) if isinstance(r, Tour)
    ]
    if not tours:
        raise StartsFailedError([r.split(": ", 1)[-1] for r in results if isinstance(r, str)])
    return min(tours, key=lambda x: (x[0], x[1]))[2]


def plan_multistart(
    cell: CellLike,
    options: Options,
    starts: int,
    engine: Engine | None = None,
    share: bool = True,
) -> Tour:
    """Plan ``starts`` independent starts of ``cell`` on ``engine`` (default: local cores).

    ``share``: compute the seed-independent part once here and hand it to the starts (the
    same tours; without it every start computes it itself)."""
    if starts < 1:
        raise PlanningError(f"starts must be at least 1, got {starts}")
    engine = engine or LocalEngine()
    started = time.perf_counter()
    seeds = start_seeds(options, starts)
    calls = [(cell, dataclasses.replace(options, seed=s)) for s in seeds]
    warm_up = getattr(engine, "warm_up", None)
    if warm_up is not None:  # workers import the planner while the shared part is computed
        # (and load the compiled search where the starts use it: planner.warm)
        compiled = len(cell.holes_in_cell()) > COMPILED_ABOVE
        warm_up([type(cell).__module__, *(["planner.warm"] if compiled else [])])
    shared_info: dict[str, float] = {}
    blob = None
    if share:
        try:
            shared = TourPlanner(options).prepare(cell)
        finally:
            gc.collect()
        t = time.perf_counter()
        blob = pack(shared)
        shared_info = {
            "shared_cpu_time_s": shared.cpu_time_s,
            "shared_bytes": len(blob),
            "shared_pack_s": time.perf_counter() - t,
        }
    results = engine.map(plan_one, calls, blob)
    best = best_tour(results, seeds)
    best.settings.update(
        {
            "multistart_base_seed": options.seed,
            "starts": starts,
            "start_seeds": seeds,
            "start_cycle_times_s": [
                r.cycle_time_s if isinstance(r, Tour) else None for r in results
            ],
            "start_cpu_times_s": [
                r.settings["cpu_time_s"] if isinstance(r, Tour) else None for r in results
            ],
            "engine": engine.name,
            "shared": share,
        }
        | shared_info
    )
    best.planning_time_s = time.perf_counter() - started
    return best
