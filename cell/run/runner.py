"""The run state machine: wait for start, thermal update on the reference targets, then for each
stop move, settle, capture, measure, compensate, compare, store; go home.

States (stored as the run's timeline): ``created`` -> ``waiting`` -> ``reference`` ->
``inspecting`` -> ``homing`` -> ``done``; ``fault`` when the controller reports an emergency stop
or fault, the link stays dead beyond the reconnect budget, or anything else fails (camera,
store, bad data); ``stopped`` when the operator interrupts. In every case the arm is stopped on
its path, the reason is recorded and the store keeps every hole measured so far. A resumed run
skips every hole already stored, so no hole is ever stored twice and nothing stored is lost.
"""

from __future__ import annotations

import logging
import sqlite3
import time
from collections import deque
from collections.abc import Callable
from concurrent.futures import Future
from contextlib import closing
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from cell.calibration.use import RunCalibration, RunGeometry, calibrated_stereo, correct_tour
from cell.camera import CameraBackend
from cell.camera.backend import computing
from cell.camera.errors import PairError
from cell.config import CellConfig
from cell.config.markers import marker_codes
from cell.errors import CellError
from cell.link import messages as m
from cell.link.client import ControllerClient
from cell.link.errors import LinkError, RunFaultError
from cell.records.hole_result import HoleResult
from cell.referencing.detection import detect_pair, label_circles
from cell.referencing.network import MarkerNetwork
from cell.review.audit_images import save_pair
from cell.review.store import Store
from cell.run.ahead import STOPS_AHEAD, Laps, PairsAhead
from cell.run.inspect import T_cell_tcp, inspect_hole, uncaptured_hole
from cell.run.reference_phase import ReferencePhase
from cell.run.referenced import ArmRegistration, LocatedStop, locate_stop, located_note
from cell.run.thermal_record import remember_model, stored_model, stored_rows
from cell.run.thermal_update import ThermalUpdate
from cell.uncertainty.context import BudgetContext, budget_context
from cell.uncertainty.decision import DEFAULT_RULE
from cell.uncertainty.part_temperature import PartThermalState, part_state
from measure import head_frame
from planner import Tour
from robots.thermal.model import ThermalModel
from robots.transforms import invert

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class RunOptions:
    """Settings of a run. Times in wall seconds unless said otherwise.

    Attributes:
        settle_s: wait after "in position" before the capture.
        move_timeout_s: longest wait for one move.
        reconnect_budget_s: how long a dead link is retried before the run stops.
        reference_rounds: rounds over the reference targets before the holes (0: none). A
            model is identified only from rounds at different temperatures, so at least two,
            ``reference_interval_s`` apart.
        reference_interval_s: controller-clock seconds between the starts of two rounds.
        part_temperature_c: the part's temperature read for this run (degC; None: the one
            stored by the run before a resume, else the cell file's or 20 degC assumed).
        u_part_temperature_K: its standard uncertainty (K; None: 0.2 K, a contact thermometer).
        decision_rule: ``iso14253`` (ISO 14253-1, with the expanded uncertainty) or ``simple``.
        keep_images: keep each stop's pair in the run directory (:mod:`cell.review.audit_images`).

    The reference temperatures of an identified model are the first reference round's readings
    (the rule of ``holecell thermal identify``), not a fixed value.
    """

    settle_s: float = 0.2
    move_timeout_s: float = 120.0
    reconnect_budget_s: float = 15.0
    reference_rounds: int = 2
    reference_interval_s: float = 300.0
    part_temperature_c: float | None = None
    u_part_temperature_K: float | None = None  # noqa: N815 (unit suffix)
    decision_rule: str = DEFAULT_RULE
    keep_images: bool = True


@dataclass
class RunResult:
    """Outcome of :meth:`Runner.run`: status (``done`` / ``fault``), holes stored by this call,
    holes skipped as already stored, timings (s; per hole: move, settle, capture (the trigger),
    render (the wait for a simulated pair still rendering), locate, inspect (of it the
    measurement itself: measure_s), store, record) and link counters."""

    status: str
    stored: list[HoleResult] = field(default_factory=list)
    skipped: list[str] = field(default_factory=list)
    timings: dict[str, float] = field(default_factory=dict)
    hole_timings: list[dict[str, float]] = field(default_factory=list)
    link: dict[str, int] = field(default_factory=dict)
    thermal: str = ""


#: ``progress(event, data)`` for the CLI: events "state", "round" (a reference round starts),
#: "reference" (a reference view measured), "hole"
Progress = Callable[[str, dict], None]


class Runner(ReferencePhase):
    """Runs one tour of one cell on one controller, storing into one run store."""

    def __init__(
        self,
        cell: CellConfig,
        tour: Tour,
        store: Store,
        client: ControllerClient,
        camera: CameraBackend,
        options: RunOptions | None = None,
        reference_tour: Tour | None = None,
        thermal_model: ThermalModel | None = None,
        progress: Progress | None = None,
        recorder=None,
        calibration: RunCalibration | None = None,
        base_from: str = "cell",
        markers: MarkerNetwork | None = None,
    ) -> None:
        self.cell, self.tour, self.store = cell, tour, store
        self.client, self.camera = client, camera
        self.options = options or RunOptions()
        self.reference_tour = reference_tour
        self.model = thermal_model
        self.progress = progress or (lambda event, data: None)
        self.recorder = recorder
        self.arm = cell.build_arm()
        target = cell.calibration_target
        # the head as triangulated: the stereo file, with the calibration's extrinsics if any;
        # a referenced run measures with the head as the survey self-calibrated it
        self.markers = markers
        self.codes = marker_codes(cell.reference_markers)
        self.registration = ArmRegistration()
        self.stereo = (markers.head if markers is not None
                       else calibrated_stereo(camera.stereo, calibration))  # fmt: skip
        self.geometry = RunGeometry(self.arm, self.stereo, calibration,
                                    None if target is None else target.T_cell_target(),
                                    base_from)  # fmt: skip
        # the commanded poses: the planned stops corrected for the calibration (unchanged
        # without one); the thermal model identifies on the calibrated geometry
        self.tour, self.corrections = correct_tour(tour, self.arm, self.geometry, "tour")
        if reference_tour is not None:
            self.reference_tour, _ = correct_tour(reference_tour, self.arm, self.geometry,
                                                  "reference tour")  # fmt: skip
        self.holes = {h.id: h for h in cell.holes_in_cell()}
        self.thermal = ThermalUpdate(cell, self.geometry)
        self._T_head_left = invert(head_frame(self.stereo))
        self.model_id: int | None = None
        self.budget: BudgetContext | None = None  # set once the reference phase is over
        self._round0 = 0
        self._loaded: Tour | None = None
        self._need_load = False

    # --- the state machine -----------------------------------------------------------------
    def run(self, wait_for_start: Callable[[], None] | None = None) -> RunResult:
        """Run (or continue) the tour; returns when home. Whatever stops it (a controller fault,
        a dead link, an interrupt, a camera or store error) stops the arm, records the run as
        ``fault`` (``stopped`` for an interrupt) with the reason, and is raised again."""
        t0 = time.perf_counter()
        result = RunResult("done")
        try:
            self._run(result, wait_for_start)
        except BaseException as exc:
            result.status = self._stopped_by(exc)
            raise
        finally:
            result.timings["run_s"] = time.perf_counter() - t0
            result.link = vars(self.client.stats).copy()
        return result

    def _run(self, result: RunResult, wait_for_start: Callable[[], None] | None) -> None:
        stored = self.store.done_ids()
        self._note_calibration()
        self._note_referencing()
        self._restore_thermal()
        self._state("waiting", holes=len(self.tour.stops), stored=len(stored))
        if wait_for_start is not None:
            wait_for_start()
        todo = [k for k, s in enumerate(self.tour.stops) if s.hole_id not in stored]
        result.skipped = [s.hole_id for s in self.tour.stops if s.hole_id in stored]
        keep_dir = self.store.path.parent if self.options.keep_images else None
        with closing(
            PairsAhead(self.camera, keep_dir, markers=(self.stereo, self.codes))
        ) as self.ahead:
            self._stops(todo, result)

    def _stops(self, todo: list[int], result: RunResult) -> None:
        """The reference phase, then every stop of ``todo``."""
        if todo and self.reference_tour is not None and self.options.reference_rounds > 0:
            self._state("reference")
            self._home_for_reference()
            self._reference_phase()
            result.thermal = self._identify()
        self.budget = self._budget_context()  # after the cold readings: no delay before them
        self._state("inspecting")
        self._load(self.tour)
        pending: deque = deque()  # stops captured, measured once the arm is STOPS_AHEAD on
        try:
            for k in todo:
                pending.append(self._capture_stop(k))
                while len(pending) > STOPS_AHEAD:
                    self._finish_stop(pending.popleft(), result)
            while pending:
                self._finish_stop(pending.popleft(), result)
        except KeyboardInterrupt:  # the operator stops the run now (a resume measures the rest)
            raise
        except BaseException:
            while pending:  # captured before the fault: measured and stored
                last = pending.popleft()
                try:
                    self._finish_stop(last, result)
                except Exception as exc:  # the fault is what the run reports
                    log.error("stop %d could not be measured after the fault: %s", last[0], exc)
            raise
        self._state("homing")
        self._move(len(self.tour.stops), "home")
        self.store.set_state("done", finished=True)
        self.progress("state", {"state": "done"})

    def _stopped_by(self, exc: BaseException) -> str:
        """Stop the arm and record why the run stopped; returns the run state it is left in."""
        if isinstance(exc, KeyboardInterrupt):
            state, message = "stopped", "interrupted by the operator"
        elif isinstance(exc, RunFaultError):
            state, message = "fault", str(exc)
        elif isinstance(exc, LinkError):
            state, message = "fault", f"link lost: {exc}"
        else:
            state, message = "fault", f"{type(exc).__name__}: {exc}"
        self._safe_stop()
        try:
            self.store.set_state(state, message)
        except (CellError, sqlite3.Error) as err:
            log.error("run %s (%s) could not be recorded: %s", state, message, err)
        self.progress("state", {"state": state, "message": message})
        if self.recorder is not None:
            self.recorder.state(state)
        return state

    def _state(self, state: str, **extra: int) -> None:
        self.store.set_state(state)
        self.progress("state", {"state": state, **extra})
        if self.recorder is not None:
            self.recorder.state(state)

    def _note_calibration(self) -> None:
        """Record which calibration the run applies and how far it moved the stops."""
        rc = self.geometry.run_calibration
        if rc is None:
            self.store.event("calibration", "no cell calibration: the cell file's kinematics, "
                             "base and head mount taken as exact")  # fmt: skip
            return
        off = [float(np.linalg.norm(c.offset_m)) for c in self.corrections]
        dq = [float(np.abs(c.dq_rad).max()) for c in self.corrections]
        self.store.event(
            "calibration",
            f"cell calibration {rc.source} ({rc.calibration.created_utc}, base from the "
            f"{self.geometry.base_from}): stops corrected by up to {max(dq, default=0.0):.2e} "
            f"rad (the calibrated head was up to {max(off, default=0.0) * 1e3:.3f} mm off "
            "the planned pose)",
        )

    def _note_referencing(self) -> None:
        if self.markers is None:
            self.store.event("referencing", "not referenced: every hole is carried into the "
                             "part by the arm's kinematics")  # fmt: skip
        else:
            m = self.markers
            self.store.event("referencing", f"referenced against {len(m.ids)} surveyed markers "
                             f"({m.source}); the head as the survey self-calibrated "
                             "it")  # fmt: skip
            if self.recorder is not None:
                self.recorder.markers(m.ids, m.positions_cell)

    # --- thermal state in the store --------------------------------------------------------
    def _restore_thermal(self) -> None:
        """Reload the stored reference observations; use the given model (stored if new) or
        else the model the run used last."""
        self.thermal.rows = stored_rows(self.store)
        self.thermal.cold_degC = self.store.thermal_reference()
        if self.thermal.cold_degC is None and self.model is not None:
            # a given model knows the cold state of this arm: identify relative to it
            self.thermal.cold_degC = tuple(self.model.spec.reference_degC)
            self.store.set_thermal_reference(self.thermal.cold_degC)
        self._round0 = 1 + max((r[5] for r in self.thermal.rows), default=-1)
        if self.model is not None:
            self.model_id = remember_model(self.store, self.model, "given (--thermal)")
        elif (latest := stored_model(self.store)) is not None:
            self.model_id, self.model = latest
            self.store.event("thermal", f"continuing with stored thermal model {self.model_id}")

    def _budget_context(self) -> BudgetContext:
        """The budget inputs: the part temperature given to this run (stored), else the one a
        resumed run stored, else the cell file's or the assumed one (stored too)."""
        o = self.options
        stored = self.store.part_state()
        if o.part_temperature_c is not None or stored is None:
            part = part_state(self.cell, o.part_temperature_c, o.u_part_temperature_K)
            self.store.set_part_state(part.to_dict())
            self.store.event("part", part.note())
        else:
            part = PartThermalState.from_dict(stored)
        return budget_context(self.cell, self.stereo, part, o.decision_rule)

    def _note_located(self, hole_id: str, located: LocatedStop) -> None:
        note = located_note(hole_id, located)
        if note is not None:
            self.store.event(*note)
            log.warning("%s", note[1])

    # --- one hole --------------------------------------------------------------------------
    def _capture_stop(self, k: int) -> tuple[int, Any, m.Status, Laps, Future]:
        """Move, settle and capture stop ``k``: its index, stop, status, laps and pair to come
        (:class:`cell.run.ahead.PairsAhead`)."""
        stop = self.tour.stops[k]
        clock = Laps()
        self._move(k, f"stop {k} ({stop.hole_id})")
        clock.lap("move_s")
        st = self._settled_status()
        clock.lap("settle_s")
        pair = self.ahead.capture(k, stop.hole_id)
        clock.lap("capture_s")
        return k, stop, st, clock, pair

    def _finish_stop(self, captured: tuple[int, Any, m.Status, Laps, Future],
                     result: RunResult) -> None:  # fmt: skip
        """Measure, compensate, compare, store, record a captured stop; add it to ``result``
        with the wall time (s) of each step."""
        k, stop, st, clock, future = captured
        with computing(self.camera):  # the arm waits at its stop while the computer works
            clock.skip()  # the next stop's move and capture: that stop's laps
            try:
                pair, kept, dets = future.result()
            except PairError as exc:  # no pair of one trigger: this stop fails, the run goes on
                hole, laps = self._uncaptured(k, stop.hole_id, exc, st, clock)
            else:
                clock.lap("render_s")
                hole, laps = self._process_pair(k, stop, pair, st, clock, kept, dets)
        result.stored.append(hole)
        result.hole_timings.append(laps)

    def _process_pair(self, k: int, stop, pair, st, clock: Laps, kept: bool, dets=None
                      ) -> tuple[HoleResult, dict[str, float]]:  # fmt: skip
        """Locate, measure, compensate, compare, store and record stop ``k``'s pair (``dets``:
        its markers, when found with its render)."""
        T_arm = (T_cell_tcp(self.geometry, self.model, st.q_rad, st.temperatures_c)
                 @ self._T_head_left)  # the arm's idea of the left camera  # fmt: skip
        located, exclude = None, None
        if self.codes:  # markers in the cell: found, so that no label is taken for the hole
            if dets is None:
                dets = detect_pair(pair.left, pair.right, self.stereo, self.codes)
            exclude = label_circles(dets)
            if self.markers is not None:
                located = locate_stop(self.markers, dets, T_arm, stop.hole_id)
                located = self.registration.place(located)
                self._note_located(stop.hole_id, located)
                clock.laps["locate_cpu_s"] = located.cpu_s
        clock.lap("locate_s")
        result, meas = inspect_hole(self.cell, self.geometry, self.model, self.stereo,
                               self.holes[stop.hole_id], k, pair.left, pair.right, st.q_rad,
                               st.temperatures_c, st.time_s, self.budget, located,
                               "" if self.markers is None else self.markers.source,
                               exclude)  # fmt: skip
        result = replace(result, thermal_model_id=self.model_id if self.model else None)
        clock.lap("inspect_s")
        self.store.record_hole(result)
        if self.options.keep_images and not kept:  # for audit and holecell remeasure
            save_pair(self.store.path.parent, k, stop.hole_id, pair.left, pair.right)
        clock.lap("store_s")
        if self.recorder is not None:
            T = located.resection.T_cell_left if located and located.referenced else T_arm
            self.recorder.hole(result, meas, pair, st, T, located)
        clock.lap("record_s")
        self.progress("hole", {"stop": k, "result": result})
        clock.laps["measure_s"] = result.measure_time_s
        return result, clock.laps

    def _uncaptured(self, k: int, hole_id: str, exc: PairError, st, clock: Laps
                    ) -> tuple[HoleResult, dict[str, float]]:  # fmt: skip
        """Store stop ``k`` as unmeasured with the camera's reason (a resume retries it)."""
        clock.lap("render_s")
        result = uncaptured_hole(self.cell, self.holes[hole_id], k, exc.reason, st.q_rad,
                                 st.temperatures_c, st.time_s)  # fmt: skip
        self.store.event("camera", f"stop {k} ({hole_id}): {exc}")
        self.store.record_hole(result)
        self.progress("hole", {"stop": k, "result": result})
        return result, clock.laps
