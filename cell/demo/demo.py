"""The whole job on the built-in cell with the simulated controller and cameras.

Plan the tour of the built-in motorcycle frame (and the reference-target tour), start the
simulated cell on a pseudo-terminal with a cold arm (in real time), let the runner take the cold
readings and measure the reference targets while the arm warms up (from the first round on, the
simulation fast-forwards the warm-up at ``warmup_speed``), identify
the thermal model, then measure every hole at ``run_speed``. Since the simulation knows the
truth, the result also holds the measurement error against it, with and without compensation.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from cell.calibration.use import RunCalibration, load_run_calibration
from cell.config import CellConfig, load_builtin_cell
from cell.demo.calibrate import (
    DemoCalibration,
    PendingCalibration,
    calibrate_demo_cell,
    start_demo_calibration_images,
)
from cell.demo.plan import plan_demo
from cell.demo.survey import (
    DemoSurvey,
    survey_demo_cell,
)
from cell.demo.truth_error import DatumError, TruthError, datum_truth_error, truth_error
from cell.demo.warm import start_demo_workers
from cell.link.client import ControllerClient
from cell.referencing.network import MarkerNetwork, load_network
from cell.referencing.survey.tour import SurveyTour
from cell.review.report import write_report
from cell.run.runner import Progress, Runner, RunOptions, RunResult
from cell.run.setup import RunFiles, check_new_run_dir, start_run
from cell.sim.faults import FaultPlan
from cell.sim.session import SimCell
from cell.sim.truth import CellTruth
from cell.sim.world import WorldOptions
from cell.uncertainty.decision import DEFAULT_RULE
from cell.uncertainty.repeatability import repeatability_rp_m
from planner import Tour
from planner.calibration import CalibrationTour
from robots.thermal.drift import DriftSettings, WarmUp, default_settings


@dataclass(frozen=True)
class DemoOptions:
    """Settings of the demo.

    Attributes:
        warmup_speed: simulation speed while the reference targets are measured (x real time).
        run_speed: simulation speed while the holes are measured.
        reference_rounds: rounds over the reference targets during the warm-up.
        reference_interval_s: simulated seconds between two rounds.
        faults: what the simulated controller does wrong (none by default).
        seed: seed of the part's true geometry, sensor noise and image noise (a ``truth``
            carries its own).
        part_temperature_c: the simulated part's true temperature (degC; None: the truth's, or
            23 degC without one); the run is given a thermometer reading of it
            (``thermometer_sigma_K`` noise, stated as ``u_part_temperature_K``).
        realistic: the simulated cell has the errors a real one has and the budget claims:
            the arm scatters by its data-sheet repeatability, the true head differs from its
            calibration by a draw from the calibration's uncertainty, the part's expansion
            coefficient by a draw from its material's (False: a perfect arm and head, no
            geometric error: :meth:`CellTruth.zero`, and no calibration).
        geometry_errors: without a ``truth``, the realistic cell also has the geometric errors
            of a real one, drawn from the seed (:meth:`CellTruth.drawn`: D-H, head mount, base,
            part and plate placement); False: none (the demo before issue 18).
        calibrate: run the cell calibration on the simulated cell first and measure the part
            with it (False: ``--no-calibration``, the nominal kinematics).
        calibration_views: views of the plate of that calibration.
        calibration_method: ``"images"`` (default): the calibration tour driven on the
            simulated cell, the plate rendered and detected in both cameras (``calibrate
            cell``'s procedure; about a minute for 120 views); ``"projected"``: the plate's
            corners projected at the planner's views (seconds, no detector; for benchmarks
            over many seeds, :mod:`cell.demo.calibrate`).
        calibration_speed: simulation speed while the calibration tour is driven (the
            simulated arm warms with the simulated time, whatever the speed).
        referencing: survey the cell's reference markers on the simulated cell (after the
            calibration) and locate every stop against them (False: ``--no-referencing``, the
            holes carried into the part by the arm). Only when the cell has markers.
        survey_speed: simulation speed while the survey tour is driven.
        thermal_scale: the arm's warm-up rises multiplied by this (a benchmark's robustness
            check: 3 is three times the reference warm-up's drift).
        truth: every hidden error of the simulated cell (a truth file, ``--truth``); None:
            the drawn truth above (or, without ``geometry_errors``, no geometric error).
        decision_rule: the run's decision rule.
        operator: the report's operator field.
        keep_images: keep each stop's pair in the run directory (as ``holecell run``).
    """

    warmup_speed: float = 1500.0
    run_speed: float = 10.0
    reference_rounds: int = 6
    reference_interval_s: float = 600.0
    faults: FaultPlan = field(default_factory=FaultPlan)
    seed: int = 0
    part_temperature_c: float | None = None
    thermometer_sigma_K: float = 0.1  # noqa: N815 (unit suffix)
    u_part_temperature_K: float = 0.2  # noqa: N815 (unit suffix)
    realistic: bool = True
    geometry_errors: bool = True
    calibrate: bool = True
    calibration_views: int = 120
    calibration_method: str = "images"
    calibration_speed: float = 10.0
    referencing: bool = True
    survey_speed: float = 20.0
    thermal_scale: float = 1.0
    decision_rule: str = DEFAULT_RULE
    operator: str = ""
    truth: CellTruth | None = None
    keep_images: bool = True


#: the demo's part temperature without a truth file or a figure (degC)
DEMO_PART_TEMPERATURE_C = 23.0


@dataclass
class DemoResult:
    """Outcome of :func:`run_demo`."""

    run_dir: Path
    tour: Tour
    run: RunResult
    summary: dict[str, Any]
    truth: TruthError
    timings: dict[str, float]
    datum: DatumError | None = None
    calibration: DemoCalibration | None = None
    survey: DemoSurvey | None = None


def run_demo(
    out_dir: str | Path,
    options: DemoOptions | None = None,
    plan_progress: Callable[[str, int, int], None] | None = None,
    run_progress: Progress | None = None,
    recorder_factory: Callable[..., Any] | None = None,
) -> DemoResult:
    """Plan, run and report the built-in cell in ``out_dir`` (created; refused before planning
    if it is a file or holds a run already). ``plan_progress`` gets every stage but the run's
    holes (``run_progress``): the planner's, the calibration tour's planning, the cell
    calibration's views and solve, the report."""
    check_new_run_dir(out_dir, resumable=False)
    opts = options or DemoOptions()
    t0 = time.perf_counter()
    cell = load_builtin_cell()
    images = opts.calibrate and opts.realistic and opts.calibration_method == "images"
    referencing = opts.referencing and bool(cell.reference_markers)
    # real time until the first reference round starts (its readings are the cold state)
    world = demo_world(cell, opts)
    start_demo_workers(cell, world)  # they warm up while this process plans
    tour, reference, caltour, planned = plan_demo(
        cell, opts.seed, plan_progress, opts.calibration_views if images else 0, referencing
    )
    t_plan = time.perf_counter() - t0
    with SimCell.start(cell, world, opts.faults) as sim:
        files = start_run(out_dir, cell, tour, "built-in tour", sim.url, reference)
        recorder = recorder_factory(Path(out_dir), cell, tour) if recorder_factory else None
        try:
            pending = _calibration(sim, files, opts, caltour, plan_progress)
            # the calibration's adjustment runs in a worker while the survey is driven
            surveyed, network = _survey(sim, files, opts, planned, plan_progress)
            cal, run_cal = _calibrated(sim, files, pending)
            result = _run_sim(sim, files, opts, _speed_up(sim, opts, run_progress), recorder,
                              run_cal, network)  # fmt: skip
            truth = truth_error(sim.world, files.store.results())
            results = files.store.results()
        finally:
            files.store.close()
            if recorder is not None:
                recorder.close()
    if plan_progress is not None:  # the report's GD&T Monte Carlo takes seconds
        plan_progress("report", 0, 2)
    summary = write_report(out_dir, opts.operator)
    if plan_progress is not None:
        plan_progress("report", 1, 2)
    datum = datum_truth_error(sim.world, results, Path(out_dir))
    if plan_progress is not None:
        plan_progress("report", 2, 2)
    timings = {"plan_s": t_plan, "run_s": result.timings["run_s"],
               "calibration_s": cal.seconds if cal else 0.0,
               "survey_s": surveyed.seconds if surveyed else 0.0,
               "total_s": time.perf_counter() - t0}  # fmt: skip
    return DemoResult(Path(out_dir), tour, result, summary, truth, timings, datum, cal, surveyed)


def _survey(
    sim: SimCell, files: RunFiles, opts: DemoOptions, planned: SurveyTour | None,
    progress: Callable[[str, int, int], None] | None = None,
) -> tuple[DemoSurvey | None, MarkerNetwork | None]:  # fmt: skip
    """Survey the simulated cell's markers (``planned``: the survey tour, None: no referencing),
    write ``markers.json`` into the run directory and load it back as the run does (checked)."""
    if planned is None:
        return None, None
    surveyed = survey_demo_cell(sim, files.cell, planned, files.store.path.parent,
                                opts.survey_speed, progress)  # fmt: skip
    return surveyed, load_network(surveyed.path, files.cell, sim.camera.stereo)


def _calibration(
    sim: SimCell, files: RunFiles, opts: DemoOptions, caltour: CalibrationTour | None,
    progress: Callable[[str, int, int], None] | None = None,
) -> PendingCalibration | DemoCalibration | None:  # fmt: skip
    """Calibrate the simulated cell (``opts.calibrate`` and a realistic cell) into the run
    directory: through images, the tour driven now and its adjustment left running in a worker
    (:func:`_calibrated` waits for it); projected, done at once; None: no calibration."""
    if not (opts.calibrate and opts.realistic):
        return None
    run_dir = files.store.path.parent
    if caltour is not None:
        return start_demo_calibration_images(sim, files.cell, caltour, run_dir,
                                             opts.calibration_speed, progress)  # fmt: skip
    return calibrate_demo_cell(sim, files.cell, files.tour, run_dir, opts.calibration_views,
                               opts.seed, progress)  # fmt: skip


def _calibrated(
    sim: SimCell, files: RunFiles, pending: PendingCalibration | DemoCalibration | None
) -> tuple[DemoCalibration | None, RunCalibration | None]:
    """The calibration of :func:`_calibration` (finished), loaded back as the run does
    (checked)."""
    if pending is None:
        return None, None
    cal = pending.finish() if isinstance(pending, PendingCalibration) else pending
    arm = files.cell.build_robot()
    return cal, load_run_calibration(cal.path, files.cell, arm, sim.camera.stereo)


def demo_world(cell: CellConfig, opts: DemoOptions) -> WorldOptions:
    """The simulated cell of the demo: real time until the first reference round (its
    readings are the cold state), the truth of :func:`demo_truth`; with ``realistic`` a true
    expansion coefficient off the material's figure, drawn from its stated uncertainty."""
    base = WorldOptions(speed=1.0, drift_offset_s=0.0, truth=demo_truth(cell, opts),
                        part_thermometer_sigma_K=opts.thermometer_sigma_K,
                        drift=_scaled_drift(opts.thermal_scale))  # fmt: skip
    if not opts.realistic:
        return base
    material, _ = cell.part_material()
    rng = np.random.default_rng([base.seed, 0xA1FA])
    alpha = material.alpha_per_K + rng.normal(0.0, material.u_alpha_per_K)
    return replace(base, part_alpha_per_K=alpha)


def _scaled_drift(k: float) -> DriftSettings | None:
    """The reference warm-up with every rise multiplied by ``k`` (None: ``k`` = 1, as is)."""
    if k == 1.0:
        return None
    d = default_settings()
    rise = tuple(WarmUp(k * w.rise_K, w.tau_s) for w in d.link_warmup)
    return replace(
        d,
        link_warmup=rise,
        sensor_warmup=tuple(WarmUp(k * w.rise_K, w.tau_s) for w in d.sensor_warmup),
    )


def demo_truth(cell: CellConfig, opts: DemoOptions) -> CellTruth:
    """``opts.truth`` (its part temperature replaced by ``part_temperature_c`` if given); without
    one and with ``realistic``: the realistic draw of the seed (:meth:`CellTruth.drawn`), or
    without ``geometry_errors`` no geometric error, the arm's data-sheet repeatability and a
    head off its calibration by a draw of its stated uncertainty; without ``realistic``:
    :meth:`CellTruth.zero`."""
    t = opts.part_temperature_c
    if opts.truth is not None:
        return opts.truth if t is None else replace(opts.truth, part_temperature_c=t)
    if opts.realistic and opts.geometry_errors:
        drawn = CellTruth.drawn(opts.seed, cell)
        return drawn if t is None else replace(drawn, part_temperature_c=t)
    truth = replace(CellTruth.zero(opts.seed),
                    part_temperature_c=DEMO_PART_TEMPERATURE_C if t is None else t)  # fmt: skip
    if not opts.realistic:
        return truth
    rp, _ = repeatability_rp_m(cell.robot.model, cell.robot.repeatability_m)
    return replace(truth, repeatability_rp_m=rp, calibration_sigma_scale=1.0)


def _speed_up(sim: SimCell, opts: DemoOptions, run_progress: Progress | None) -> Progress:
    """Progress that fast-forwards the warm-up (``warmup_speed``) once the first reference
    round has taken the cold readings, switches to ``run_speed`` for the holes, and passes
    every event on."""

    def progress(event: str, data: dict) -> None:
        if event == "round" and data["round"] == 0:
            sim.world.clock.set_speed(opts.warmup_speed)
        if event == "state" and data["state"] == "inspecting":
            sim.world.clock.set_speed(opts.run_speed)
        if run_progress is not None:
            run_progress(event, data)

    return progress


def _run_sim(
    sim: SimCell,
    files: RunFiles,
    opts: DemoOptions,
    progress: Progress,
    recorder: Any,
    calibration: RunCalibration | None = None,
    network: MarkerNetwork | None = None,
) -> RunResult:
    """Run the stored tour on the simulated cell over its port (referenced against
    ``network`` when given)."""
    run_opts = RunOptions(
        settle_s=0.2 / opts.run_speed,
        reference_rounds=opts.reference_rounds,
        reference_interval_s=opts.reference_interval_s,
        part_temperature_c=sim.world.part_reading_c(),
        u_part_temperature_K=opts.u_part_temperature_K,
        decision_rule=opts.decision_rule,
        keep_images=opts.keep_images,
    )
    with ControllerClient(sim.url) as client:
        runner = Runner(files.cell, files.tour, files.store, client, sim.camera, run_opts,
                        files.reference, None, progress, recorder, calibration,
                        markers=network)  # fmt: skip
        return runner.run()
