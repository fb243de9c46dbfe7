"""The whole job on the built-in cell with the simulated controller and cameras.

Plan the tour of the built-in motorcycle frame (and the reference-target tour), start the
simulated cell on a pseudo-terminal with a cold arm (in real time), let the runner take the cold
readings and measure the reference targets while the arm warms up (from the first round on, the
simulation fast-forwards the warm-up at ``warmup_speed``), identify
the thermal model, then measure every hole at ``run_speed``. Since the simulation knows the
truth, the result also holds the measurement error against it, with and without compensation.
"""

from __future__ import annotations

import logging
import multiprocessing
import time
from collections.abc import Callable
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from cell.config import CellConfig, load_builtin_cell
from cell.link.client import ControllerClient
from cell.review.report import write_report
from cell.run.reference import plan_reference_tour
from cell.run.results import HoleResult, deviations
from cell.run.runner import Progress, Runner, RunOptions, RunResult
from cell.run.setup import RunFiles, check_new_run_dir, start_run
from cell.sim.faults import FaultPlan
from cell.sim.session import SimCell
from cell.sim.truth import CellTruth
from cell.sim.world import SimWorld, WorldOptions
from cell.uncertainty.decision import DEFAULT_RULE
from cell.uncertainty.repeatability import repeatability_rp_m
from planner import Options, Tour, TourPlanner
from planner.tour import tour_from_dict
from robots.transforms import invert


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
            geometric error: :meth:`CellTruth.zero`).
        truth: every hidden error of the simulated cell (a truth file, ``--truth``); None:
            no geometric error, and with ``realistic`` the repeatability and head draw above.
        decision_rule: the run's decision rule.
        operator: the report's operator field.
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
    decision_rule: str = DEFAULT_RULE
    operator: str = ""
    truth: CellTruth | None = None


#: the demo's part temperature without a truth file or a figure (degC)
DEMO_PART_TEMPERATURE_C = 23.0


@dataclass
class TruthError:
    """Measured minus true hole centres (m, part frame, at 20 degC) over the measured holes;
    ``coverage``: the fraction of measured characteristics (position deviation and diameter of
    each hole) whose true value lies within the stated expanded uncertainty (NaN: none)."""

    rms_m: float
    max_m: float
    rms_uncompensated_m: float
    diameter_rms_m: float
    n: int
    coverage: float = float("nan")
    n_covered: int = 0
    n_characteristics: int = 0
    position_covered: list[bool] = field(default_factory=list)
    diameter_covered: list[bool] = field(default_factory=list)
    rms_in_plane_m: float = float("nan")
    max_in_plane_m: float = float("nan")


@dataclass
class DemoResult:
    """Outcome of :func:`run_demo`."""

    run_dir: Path
    tour: Tour
    run: RunResult
    summary: dict[str, Any]
    truth: TruthError
    timings: dict[str, float]


def truth_error(world: SimWorld, results: list[HoleResult]) -> TruthError:
    """Measurement error against the simulation's true holes (their 20 degC geometry), and the
    coverage of the stated uncertainties: ``|d - d_true| <= U_position`` for the position
    deviation (in the plane of the nominal axis) and ``|D - D_true| <= U_diameter``."""
    T_part_cell = invert(world.T_cell_part)  # the true part frame: the part as it lies
    normals = {h.id: np.asarray(h.normal, float) for h in world.cell.part.holes}
    e, e_u, e_d, e_p, cov_p, cov_d = [], [], [], [], [], []
    for r in results:
        if r.center_part_m is None:
            continue
        h = world.holes[r.hole_id]
        true_c = T_part_cell[:3, :3] @ h.position_m + T_part_cell[:3, 3]
        e.append(np.linalg.norm(np.array(r.center_part_m) - true_c))
        e_u.append(np.linalg.norm(np.array(r.extra["center_part_uncompensated_m"]) - true_c))
        e_d.append(r.diameter_m - h.diameter_m)
        n = normals[r.hole_id]
        err = np.array(r.center_part_m) - true_c
        e_p.append(np.linalg.norm(err - (err @ n) * n))
        if r.U_position_m is not None:
            nom = np.array(r.nominal_part_m)
            d_true = deviations(true_c, h.diameter_m, nom, r.nominal_diameter_m, None,
                                normals[r.hole_id])[0]  # fmt: skip
            cov_p.append(bool(abs(r.position_deviation_m - d_true) <= r.U_position_m))
            cov_d.append(bool(abs(r.diameter_m - h.diameter_m) <= r.U_diameter_m))

    def rms(v: list[float]) -> float:
        return float(np.sqrt(np.mean(np.square(v)))) if v else float("nan")

    covered = cov_p + cov_d
    cov = float(np.mean(covered)) if covered else float("nan")
    return TruthError(rms(e), float(max(e, default=float("nan"))), rms(e_u), rms(e_d), len(e),
                      cov, int(np.sum(covered)), len(covered), cov_p, cov_d, rms(e_p),
                      float(max(e_p, default=float("nan"))))  # fmt: skip


def _plan_reference(seed: int) -> dict[str, Any]:
    # views the arm cannot reach are expected; the tour lists them in left_out
    logging.getLogger("planner").setLevel(logging.ERROR)
    return plan_reference_tour(load_builtin_cell(), Options(seed=seed)).to_dict()


def plan_demo(
    cell: CellConfig, seed: int, plan_progress: Callable[[str, int, int], None] | None = None
) -> tuple[Tour, Tour]:
    """The hole tour and the reference tour of ``cell``; the reference tour is planned in a
    second process while this one plans the holes. The second process is started by a fork
    server, not forked from this one: a process that has run a simulator or a planner holds
    threads (and their locks) that a forked child would inherit locked."""
    ctx = multiprocessing.get_context("forkserver")
    with ProcessPoolExecutor(max_workers=1, mp_context=ctx) as pool:
        ref_job = pool.submit(_plan_reference, seed)
        tour = TourPlanner(Options(seed=seed), plan_progress).plan(cell)
        reference = tour_from_dict(ref_job.result(), "reference tour")
    return tour, reference


def run_demo(
    out_dir: str | Path,
    options: DemoOptions | None = None,
    plan_progress: Callable[[str, int, int], None] | None = None,
    run_progress: Progress | None = None,
    recorder_factory: Callable[..., Any] | None = None,
) -> DemoResult:
    """Plan, run and report the built-in cell in ``out_dir`` (created; refused before planning
    if it is a file or holds a run already)."""
    check_new_run_dir(out_dir, resumable=False)
    opts = options or DemoOptions()
    t0 = time.perf_counter()
    cell = load_builtin_cell()
    tour, reference = plan_demo(cell, opts.seed, plan_progress)
    t_plan = time.perf_counter() - t0
    # real time until the first reference round starts (its readings are the cold state)
    world = demo_world(cell, opts)
    with SimCell.start(cell, world, opts.faults) as sim:
        files = start_run(out_dir, cell, tour, "built-in tour", sim.url, reference)
        recorder = recorder_factory(Path(out_dir), cell, tour) if recorder_factory else None
        try:
            result = _run_sim(sim, files, opts, _speed_up(sim, opts, run_progress), recorder)
            truth = truth_error(sim.world, files.store.results())
        finally:
            files.store.close()
            if recorder is not None:
                recorder.close()
    summary = write_report(out_dir, opts.operator)
    timings = {"plan_s": t_plan, "run_s": result.timings["run_s"],
               "total_s": time.perf_counter() - t0}  # fmt: skip
    return DemoResult(Path(out_dir), tour, result, summary, truth, timings)


def demo_world(cell: CellConfig, opts: DemoOptions) -> WorldOptions:
    """The simulated cell of the demo: real time until the first reference round (its
    readings are the cold state), the truth of :func:`demo_truth`; with ``realistic`` a true
    expansion coefficient off the material's figure, drawn from its stated uncertainty."""
    base = WorldOptions(speed=1.0, drift_offset_s=0.0, truth=demo_truth(cell, opts),
                        part_thermometer_sigma_K=opts.thermometer_sigma_K)  # fmt: skip
    if not opts.realistic:
        return base
    material, _ = cell.part_material()
    rng = np.random.default_rng([base.seed, 0xA1FA])
    alpha = material.alpha_per_K + rng.normal(0.0, material.u_alpha_per_K)
    return replace(base, part_alpha_per_K=alpha)


def demo_truth(cell: CellConfig, opts: DemoOptions) -> CellTruth:
    """``opts.truth`` (its part temperature replaced by ``part_temperature_c`` if given); without
    one no geometric error and, with ``realistic``, the arm's data-sheet repeatability and a
    head off its calibration by a draw of its stated uncertainty."""
    t = opts.part_temperature_c
    if opts.truth is not None:
        return opts.truth if t is None else replace(opts.truth, part_temperature_c=t)
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
    sim: SimCell, files: RunFiles, opts: DemoOptions, progress: Progress, recorder: Any
) -> RunResult:
    """Run the stored tour on the simulated cell over its port."""
    run_opts = RunOptions(
        settle_s=0.2 / opts.run_speed,
        reference_rounds=opts.reference_rounds,
        reference_interval_s=opts.reference_interval_s,
        part_temperature_c=sim.world.part_reading_c(),
        u_part_temperature_K=opts.u_part_temperature_K,
        decision_rule=opts.decision_rule,
    )
    with ControllerClient(sim.url) as client:
        runner = Runner(files.cell, files.tour, files.store, client, sim.camera, run_opts,
                        files.reference, None, progress, recorder)  # fmt: skip
        return runner.run()
