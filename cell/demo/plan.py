"""The demo's tours: the holes', the reference targets', the calibration's and the survey's.

All four are deterministic per cell, seed and code: each is read from the user's cache folder
(:mod:`cell.demo.caltour_cache`) when it is there. Otherwise the hole tour is planned in this
process, with the planner's progress (the first run shows the planning), and the other three
in worker processes meanwhile; all are cached.
"""

from __future__ import annotations

import logging
import multiprocessing
from collections.abc import Callable
from concurrent.futures import Future, ProcessPoolExecutor
from typing import Any

from cell.camera import cell_stereo
from cell.config import CellConfig, load_builtin_cell
from cell.demo.calibrate import plan_demo_caltour
from cell.demo.caltour_cache import cached_plan, plan_key
from cell.demo.survey import plan_demo_survey, survey_tour_from_dict
from cell.referencing.survey.tour import SurveyTour
from cell.referencing.viewpoints import MarkerAwarePlanner
from cell.run.reference import plan_reference_tour
from planner import Options, Tour, TourPlanner
from planner.calibration import CalibrationTour, caltour_from_dict
from planner.cell_identity import cell_sha256
from planner.tour import tour_from_dict

#: the source that decides the hole tour (its cache key)
HOLE_PLAN_CODE = ("planner", "robots", "cell/referencing", "cell/camera", "cell/demo",
                  "cell/config")  # fmt: skip
#: the source that decides the reference tour (its cache key)
REFERENCE_PLAN_CODE = ("planner", "robots", "cell/run", "cell/demo", "cell/config")


def plan_demo_reference(seed: int, cached_only: bool = False) -> dict[str, Any] | None:
    """The built-in cell's reference-target tour (JSON-ready), planned once per cell, seed and
    code and then read from the user's cache folder; ``cached_only``: None when it is not
    cached."""
    cell = load_builtin_cell()

    def plan() -> dict[str, Any]:
        # views the arm cannot reach are expected; the tour lists them in left_out
        logging.getLogger("planner").setLevel(logging.ERROR)
        return plan_reference_tour(cell, Options(seed=seed)).to_dict()

    key = plan_key({"plan": "reference", "cell": cell_sha256(cell), "seed": seed},
                   REFERENCE_PLAN_CODE)  # fmt: skip
    found = cached_plan("reference", key, None if cached_only else plan, tour_from_dict)
    return None if found is None else found[0]


def _hole_tour(
    cell: CellConfig, seed: int, markers: bool,
    plan_progress: Callable[[str, int, int], None] | None,
) -> Tour:  # fmt: skip
    """The hole tour (``markers``: the viewpoints chosen to see the markers), planned here with
    the planner's progress the first time, then read from the user's cache folder; its
    ``settings["plan_cache"]`` says which."""

    def plan() -> dict[str, Any]:
        planner = (
            MarkerAwarePlanner(cell, cell_stereo(cell), Options(seed=seed), plan_progress)
            if markers
            else TourPlanner(Options(seed=seed), plan_progress)
        )
        return planner.plan(cell).to_dict()

    key = plan_key({"plan": "holes", "cell": cell_sha256(cell), "seed": seed,
                    "markers": markers}, HOLE_PLAN_CODE)  # fmt: skip
    found = cached_plan("holes", key, plan, tour_from_dict)
    assert found is not None  # planned when missing
    data, note = found
    tour = tour_from_dict(data, "hole tour")
    tour.settings["plan_cache"] = note
    return tour


def plan_demo(
    cell: CellConfig,
    seed: int,
    plan_progress: Callable[[str, int, int], None] | None = None,
    caltour_views: int = 0,
    survey: bool = False,
) -> tuple[Tour, Tour, CalibrationTour | None, SurveyTour | None]:
    """The hole tour, the reference tour, (``caltour_views`` > 0) the calibration tour and
    (``survey``) the survey tour of ``cell``; those of the last three not cached are planned in
    worker processes while this one plans the holes.
    The workers are started by a fork server, not forked from this one: a process that has
    run a simulator or a planner holds threads (and their locks) that a forked child would
    inherit locked."""
    jobs: dict[str, tuple[Callable[..., Any], tuple]] = {
        "reference": (plan_demo_reference, (seed,))}  # fmt: skip
    if caltour_views:
        jobs["caltour"] = (plan_demo_caltour, (caltour_views, seed))
    if survey:
        jobs["survey"] = (plan_demo_survey, (seed,))
    found = {name: fn(*args, cached_only=True) for name, (fn, args) in jobs.items()}
    misses = [name for name in jobs if found[name] is None]
    pool = None
    if misses:
        ctx = multiprocessing.get_context("forkserver")
        pool = ProcessPoolExecutor(max_workers=min(2, len(misses)), mp_context=ctx)
    try:
        futures: dict[str, Future] = {
            name: pool.submit(jobs[name][0], *jobs[name][1])
            for name in misses  # type: ignore[union-attr]
        }
        tour = _hole_tour(cell, seed, survey, plan_progress)
        if "caltour" in futures and plan_progress is not None:  # may still be planning
            plan_progress("calibration tour", int(futures["caltour"].done()), 1)
        done = {**found, **{name: f.result() for name, f in futures.items()}}
    finally:
        if pool is not None:
            pool.shutdown(wait=True, cancel_futures=True)
    if caltour_views and plan_progress is not None:
        plan_progress("calibration tour", 1, 1)
    reference = tour_from_dict(done["reference"], "reference tour")
    caltour = caltour_from_dict(done["caltour"], "caltour") if caltour_views else None
    planned = survey_tour_from_dict(done["survey"]) if survey else None
    return tour, reference, caltour, planned
