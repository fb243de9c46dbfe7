"""The demo's first step: calibrate the simulated cell, and how good that calibration is.

Two ways (``DemoOptions.calibration_method``):

- ``"images"``: :func:`calibrate_demo_cell_images` runs the calibration tour (planned as
  ``holecell calibrate cell`` plans it, :func:`plan_demo_caltour`) on the simulated controller
  and head with :func:`cell.calibration.capture.tour.run_calibration_tour`: the plate rendered in
  both cameras at every view, detected, one adjustment. The whole procedure of a real cell.
- ``"projected"``: :func:`calibrate_demo_cell` (:mod:`cell.demo.sim_calibration`): the plate's
  corners projected through the simulated cell's true geometry at the planner's feasible views
  chosen over the hole tour's joint range, corner noise and the arm's repeatability added, one
  adjustment. Seconds instead of minutes; no detector, no tour driven.

Either writes ``RUN_DIR/cellcal.json`` and measures the estimate against the simulation's
truth (the hand-eye in the calibration's gauge: the structurally redundant D-H terms folded
into it, :func:`cell.calibration.estimate.synthetic.truth_in_gauge`).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from concurrent.futures import Future
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from cell.calibration.capture.tour import CapturedTour, finish_calibration_tour, solve_captured
from cell.calibration.estimate import CellCalibration, SolveOptions, pose_error, truth_in_gauge
from cell.calibration.file import save_calibration
from cell.calibration.use import RUN_FILENAME
from cell.camera.workers import executor
from cell.config import CellConfig
from cell.demo.caltour_cache import cached_caltour, caltour_key
from cell.demo.sim_calibration import design_views, simulated_calibration, synthetic_truth
from cell.sim.session import SimCell
from planner import Tour
from planner.calibration import CalibrationTour

#: the demo's calibration tour is chosen by the geometric pre-selection (rotations, image
#: cover, the hole tour's joint range), without the predicted sigma: as accurate here as the
#: I-optimal design (docs/calibration.md, "The demo") and 45 s less planning
CALTOUR_CRITERION = "geometric"


@dataclass(frozen=True)
class DemoCalibration:
    """The demo's calibration: the file, its estimate, the wall time (s), the hand-eye's error
    against the truth (m, rad), the D-H terms fixed and the method."""

    path: Path
    calibration: CellCalibration
    seconds: float
    hand_eye_error_m: float
    hand_eye_error_rad: float
    fixed_terms: tuple[str, ...]
    method: str
    tour_note: str = ""  # how the calibration tour was had (planned, or from the cache)

    @property
    def hand_eye_sigma_m(self) -> float:
        """Root sum of the hand-eye's position variances (m)."""
        return float(np.linalg.norm(self.calibration.T_tool0_camera.sigma_xyz_m))

    @property
    def hand_eye_sigma_rad(self) -> float:
        """Root sum of the hand-eye's rotation variances (rad)."""
        return float(np.linalg.norm(self.calibration.T_tool0_camera.sigma_rot_rad))


#: a stage's progress: (stage, done, total), as the planner's (cell.commands.plan_cmd.StageBars)
StageProgress = Callable[[str, int, int], None]


def tour_stages(progress: StageProgress | None) -> Callable[[str, dict], None] | None:
    """The calibration tour's events (:func:`run_calibration_tour`'s ``progress``) as two
    stages: ``calibration`` (views captured and their target detected, of the tour's) and
    ``solve`` (the adjustment: 0 of 1, then 1 of 1)."""
    if progress is None:
        return None

    def report(event: str, data: dict) -> None:
        if event == "view":
            progress("calibration", data["k"] + 1, data["n"])
        elif event == "solve":
            progress("solve", 0, 1)
        elif event == "done":
            progress("solve", 1, 1)

    return report


def calibrate_demo_cell(
    sim: SimCell, cell: CellConfig, tour: Tour, run_dir: Path, views: int, seed: int,
    progress: StageProgress | None = None,
) -> DemoCalibration:  # fmt: skip
    """Calibrate the simulated cell of ``sim`` for the hole tour ``tour`` (its joint range)
    and write ``run_dir/cellcal.json``; ``progress`` gets the ``calibration`` stage (designing
    the views, then solving)."""
    t0 = time.perf_counter()
    if progress is not None:
        progress("calibration", 0, 2)
    geometry = sim.world.true_geometry()
    stereo = sim.camera.stereo
    q_views = design_views(cell, stereo, np.array([s.q for s in tour.stops]), views)
    if progress is not None:
        progress("calibration", 1, 2)
    res = simulated_calibration(cell, geometry, stereo, sim.world.truth.repeatability_rp_m,
                                q_views, seed=seed, true_stereo=sim.camera.true_stereo)  # fmt: skip
    path = Path(run_dir) / RUN_FILENAME
    save_calibration(res.calibration, path)
    if progress is not None:
        progress("calibration", 2, 2)
    seconds = time.perf_counter() - t0
    gauge = truth_in_gauge(synthetic_truth(cell, geometry, stereo))
    dp, dr = pose_error(res.calibration.T_tool0_camera.T, gauge.T_tool0_camera)
    fixed = tuple(t.name for t in res.calibration.dh_terms if not t.free)
    method = (f"{len(q_views)} views of the plate (planner's feasible views; corners projected "
              "through the simulated cell, not rendered)")  # fmt: skip
    return DemoCalibration(path, res.calibration, seconds, dp, dr, fixed, method)


def plan_demo_caltour(views: int, seed: int, cached_only: bool = False) -> dict | None:
    """The built-in cell's calibration tour as ``holecell calibrate cell`` plans it (JSON-ready:
    planned in a worker process), planned once per cell, view count, seed and code and then
    read from the user's cache folder (:mod:`cell.demo.caltour_cache`; its ``settings``
    key ``plan_cache`` says which); ``cached_only``: None when it is not cached."""
    from cell.calibration.plan import calibrate_plan_options, plan_cell_calibration
    from cell.camera import cell_stereo
    from cell.config import load_builtin_cell

    cell = load_builtin_cell()
    opts = replace(calibrate_plan_options(views, seed), criterion=CALTOUR_CRITERION,
                   predict=False)  # fmt: skip
    found = cached_caltour(
        caltour_key(cell, opts, views, seed),
        None if cached_only else lambda: plan_cell_calibration(cell, cell_stereo(cell),
                                                               opts).to_dict(),
    )  # fmt: skip
    if found is None:
        return None
    data, note = found
    data.setdefault("settings", {})["plan_cache"] = note  # printed with the calibration
    return data


def calibrate_demo_cell_images(
    sim: SimCell, cell: CellConfig, caltour: CalibrationTour, run_dir: Path, speed: float,
    progress: StageProgress | None = None,
) -> DemoCalibration:  # fmt: skip
    """Run ``caltour`` on the simulated cell at ``speed`` (x real time), detect, solve
    (:func:`cell.calibration.capture.tour.run_calibration_tour`); write ``run_dir/cellcal.json``;
    ``progress`` gets the stages of :func:`tour_stages`."""
    pending = start_demo_calibration_images(sim, cell, caltour, run_dir, speed, progress)
    if progress is not None:
        progress("solve", 0, 1)
    cal = pending.finish()
    if progress is not None:
        progress("solve", 1, 1)
    return cal


@dataclass
class PendingCalibration:
    """A demo calibration whose tour is captured and whose adjustment runs in a worker process
    (:func:`start_demo_calibration_images`); :meth:`finish` waits for it and writes the file."""

    sim: SimCell
    cell: CellConfig
    caltour: CalibrationTour
    run_dir: Path
    captured: CapturedTour
    options: SolveOptions
    solve: Future
    progress: StageProgress | None
    captured_s: float  # the tour's wall time (s)

    def finish(self) -> DemoCalibration:
        """The adjustment's result (its refusals raised here), written to
        ``run_dir/cellcal.json`` and measured against the simulation's truth."""
        t0 = time.perf_counter()  # the solve's own time is in the summary, not in a bar
        try:
            solved = self.solve.result()
        except BrokenProcessPool:  # the worker died (memory?): solved here instead
            solved = solve_captured(self.captured, self.options)
        run = finish_calibration_tour(self.captured, solved)
        cal = run.result.calibration
        path = Path(self.run_dir) / RUN_FILENAME
        save_calibration(cal, path)
        seconds = self.captured_s + time.perf_counter() - t0  # the survey's time left out
        sim = self.sim
        gauge = truth_in_gauge(synthetic_truth(self.cell, sim.world.true_geometry(),
                                               sim.camera.stereo))  # fmt: skip
        dp, dr = pose_error(cal.T_tool0_camera.T, gauge.T_tool0_camera)
        fixed = tuple(t.name for t in cal.dh_terms if not t.free)
        method = (f"calibration tour of {len(self.caltour.tour.stops)} views driven on the "
                  f"simulated controller ({run.captures.robot_time_s:.0f} s robot time), plate "
                  f"rendered and detected in both cameras, solve "
                  f"{run.result.timings['total_s']:.1f} s in a worker process"
                  + ("" if run.warming is None else f"; {run.warming.line()}"))  # fmt: skip
        note = str(self.caltour.tour.settings.get("plan_cache", ""))
        return DemoCalibration(path, cal, seconds, dp, dr, fixed, method, note)


def start_demo_calibration_images(
    sim: SimCell, cell: CellConfig, caltour: CalibrationTour, run_dir: Path, speed: float,
    progress: StageProgress | None = None,
) -> PendingCalibration:  # fmt: skip
    """Drive ``caltour`` on the simulated cell at ``speed`` (x real time) and detect the plate
    (:func:`cell.calibration.capture.tour.capture_calibration_tour`), then hand the adjustment
    to one of the process's workers (:func:`cell.camera.workers.executor`): the survey can run
    meanwhile, it needs no cell calibration."""
    from cell.calibration.capture import (
        CalibrateCellOptions,
        CaptureSettings,
        capture_calibration_tour,
    )
    from cell.link.client import ControllerClient

    t0 = time.perf_counter()
    sim.world.clock.set_speed(speed)
    try:
        opts = CalibrateCellOptions(
            capture=CaptureSettings(settle_s=0.2 / speed),
            solve=SolveOptions(estimate_intrinsics=True),
            max_warming_K=float("inf"),  # the demo calibrates its cold arm: reported, not refused
        )  # as the CLI
        with ControllerClient(sim.url) as client:
            captured = capture_calibration_tour(cell, caltour, client, sim.camera, opts,
                                                tour_stages(progress))  # fmt: skip
    finally:
        sim.world.clock.set_speed(1.0)
    solve = executor(opts.capture.workers).submit(solve_captured, captured, opts.solve)
    return PendingCalibration(sim, cell, caltour, run_dir, captured, opts.solve, solve, progress,
                              time.perf_counter() - t0)  # fmt: skip
