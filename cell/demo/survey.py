"""The survey on the simulated cell: the survey tour driven on the simulated controller, the
markers rendered and detected in both cameras, one adjustment (``holecell survey``'s
procedure), ``markers.json`` written into the run directory, and the network compared with the
simulator's true markers."""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from cell.config import CellConfig
from cell.demo.caltour_cache import cached_plan, plan_key
from cell.referencing import save_markers
from cell.referencing.markersfile import MARKERS_FILENAME
from cell.referencing.survey.gauge import rigid_fit
from cell.referencing.survey.result import SurveyResult
from cell.referencing.survey.run import SurveyRunOptions, run_survey
from cell.referencing.survey.tour import SurveyTour
from cell.sim.session import SimCell


@dataclass(frozen=True)
class DemoSurvey:
    """The survey's file, result, wall time (s), robot time (s), adjustment time (s) and its
    error against the true markers: after a rigid fit (RMS and worst, m), the scale error (ppm,
    from all the markers' distances), the share of coordinates within their stated 2 sigma (the
    truth taken into the survey's gauge)."""

    path: Path
    result: SurveyResult
    seconds: float
    robot_time_s: float
    rms_m: float
    worst_m: float
    solve_s: float = float("nan")
    scale_error_ppm: float = float("nan")
    within_2sigma: float = float("nan")
    plan_cache: str = ""
    #: the survey tour's planned robot time (s): motion and the 0.2 s settle per view; the
    #: simulator's clock (``robot_time_s``) also runs while each pair renders
    planned_robot_time_s: float = float("nan")


#: the centre-noise floor of the simulated head (px): it states its own noise, the survey's a
#: posteriori figure (0.006 px on the renderer's images), where a real head states
#: :data:`cell.referencing.sigma.SIGMA_FLOOR_PX` (docs/referencing.md, "The floor")
SIM_SIGMA_FLOOR_PX = 0.0

#: the source that decides the survey tour (its cache key)
SURVEY_PLAN_CODE = ("planner", "robots", "cell/referencing", "cell/demo", "cell/config")


def plan_demo_survey(seed: int, cached_only: bool = False) -> dict | None:
    """The built-in cell's survey tour as ``holecell survey`` plans it (JSON-ready: planned in a
    worker process), planned once per cell, seed and code and then read from the user's cache
    folder (:mod:`cell.demo.caltour_cache`; ``plan_cache`` says which); ``cached_only``: None
    when it is not cached."""
    from cell.camera import cell_stereo
    from cell.config import load_builtin_cell
    from cell.referencing.survey.tour import plan_survey_tour
    from planner import Options
    from planner.cell_identity import cell_sha256

    cell = load_builtin_cell()

    def plan() -> dict:
        planned = plan_survey_tour(cell, cell_stereo(cell), options=Options(seed=seed))
        return {"tour": planned.tour.to_dict(),
                "T_cell_left": {k: v.tolist() for k, v in planned.T_cell_left.items()},
                "left_out": planned.left_out}  # fmt: skip

    key = plan_key({"plan": "survey", "cell": cell_sha256(cell), "seed": seed},
                   SURVEY_PLAN_CODE)  # fmt: skip
    found = cached_plan("survey", key, None if cached_only else plan,
                        lambda d, src: survey_tour_from_dict(d))  # fmt: skip
    if found is None:
        return None
    data, note = found
    data["plan_cache"] = note
    return data


def _views(progress: Callable[[str, int, int], None] | None) -> Callable[[str, dict], None] | None:
    """The survey's "view" events as the ``survey`` stage."""
    if progress is None:
        return None

    def report(event: str, data: dict) -> None:
        if event == "view":
            progress("survey", data["k"], data["n"])

    return report


def survey_tour_from_dict(data: dict) -> SurveyTour:
    """The inverse of :func:`plan_demo_survey`."""
    from planner.tour import tour_from_dict

    return SurveyTour(tour_from_dict(data["tour"], "survey tour"),
                      {k: np.asarray(v, float) for k, v in data["T_cell_left"].items()},
                      dict(data["left_out"]), str(data.get("plan_cache", "")))  # fmt: skip


def survey_demo_cell(
    sim: SimCell, cell: CellConfig, planned: SurveyTour, run_dir: Path, speed: float,
    progress: Callable[[str, int, int], None] | None = None,
) -> DemoSurvey:  # fmt: skip
    """Run the survey tour at ``speed`` (x real time), adjust, write ``run_dir/markers.json``;
    ``progress`` gets the ``survey`` stage (views detected, of the tour's)."""
    from cell.link.client import ControllerClient

    t0 = time.perf_counter()
    sim.world.clock.set_speed(speed)
    try:
        with ControllerClient(sim.url) as client:
            done = run_survey(cell, planned, client, sim.camera, sim.camera.stereo,
                              SurveyRunOptions(settle_s=0.2 / speed,
                                               sigma_floor_px=SIM_SIGMA_FLOOR_PX),
                              _views(progress))  # fmt: skip
    finally:
        sim.world.clock.set_speed(1.0)
    path = Path(run_dir) / MARKERS_FILENAME
    save_markers(path, done.result, cell, sim.camera.stereo)
    mt = sim.world.markers
    r = done.result
    rows = [mt.ids.index(m) for m in r.marker_ids]
    true = mt.true[rows]
    F = rigid_fit(r.positions_cell, true)
    e = np.linalg.norm(r.positions_cell @ F[:3, :3].T + F[:3, 3] - true, axis=1)
    P = r.positions_cell
    d_est = np.linalg.norm(P[:, None] - P[None], axis=2)
    d_true = np.linalg.norm(true[:, None] - true[None], axis=2)
    scale = 1e6 * (np.sum(d_est * d_true) / np.sum(d_true**2) - 1.0)
    # the survey's gauge: its fixture markers (or all of them) fitted to nominal
    fixture = mt.on_fixture[rows] if r.gauge == "fixture markers" else np.ones(len(rows), bool)
    G = rigid_fit(true[fixture], mt.nominal[rows][fixture])
    z = np.abs(P - (true @ G[:3, :3].T + G[:3, 3])) / r.sigma_m()
    return DemoSurvey(path, r, time.perf_counter() - t0, done.captures.robot_time_s,
                      float(np.sqrt(np.mean(e**2))), float(e.max()), done.solve_s, float(scale),
                      float(np.mean(z < 2.0)), planned.plan_cache,
                      float(planned.tour.cycle_time_s))  # fmt: skip
