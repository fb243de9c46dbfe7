"""Running the survey tour: move to each view, settle, capture a stereo pair, detect and
identify the markers in both images (:func:`cell.referencing.detection.observe_pair`).

The arm moves with the run's machinery (:class:`cell.link.motion.Motion`: reload, reconnect
within a budget, stop safely on a fault). Each view's prior is its planned left-camera pose
(the arm's idea of it): it removes the perspective bias of the markers' centres and starts the
adjustment.

The views' detections run in ``workers`` processes while the arm moves on (the survey's images
are many: on two cores, two at a time), the simulated head's renders too
(:mod:`cell.camera.workers`), so the arm never waits for a render. The views are collected
in the tour's order, and a view's result depends only on its images: the same captures give the
same views with any number of workers (``workers=0``: in this process, one view after another).
"""

from __future__ import annotations

import logging
import time
from collections import deque
from collections.abc import Callable, Mapping
from concurrent.futures import Future
from dataclasses import dataclass, field

import numpy as np

from cell.camera import CameraBackend
from cell.camera.workers import (
    PAIRS_WAITING_PER_WORKER,
    PairSource,
    executor,
    pair_source,
    rendered,
)
from cell.config import CellConfig
from cell.config.markers import marker_codes, marker_in_cell
from cell.link.client import ControllerClient
from cell.link.motion import Motion
from cell.referencing.detection import MarkerGeometry, observe_pair
from cell.referencing.observations import MarkerView
from cell.referencing.survey.tour import SurveyTour
from measure import StereoCalibration

log = logging.getLogger(__name__)

#: ``progress(event, data)``: "view" after each view (``k``, ``n``, ``id``, ``markers``)
Progress = Callable[[str, dict], None]


@dataclass(frozen=True)
class SurveyCaptureSettings:
    """Wait after "in position" (s), longest move (s), how long a dead link is retried (s),
    the processes that render and detect (0: this process, one view after another)."""

    settle_s: float = 0.2
    move_timeout_s: float = 120.0
    reconnect_budget_s: float = 15.0
    workers: int = 2


@dataclass
class SurveyCaptures:
    """Every view's markers, the controller clock at the start and the end (s) and the wall
    time of each step (s): ``move_s``, ``capture_s`` (the trigger, and the render when it is
    not deferred), ``wait_s`` (for the last detections after the tour); summed over the views
    wherever they ran: ``render_s`` (deferred renders), ``detect_s`` and ``cpu_s`` (the render's
    and the detection's CPU time)."""

    views: list[MarkerView]
    start_time_s: float
    end_time_s: float
    wall_s: dict[str, float] = field(default_factory=dict)

    @property
    def robot_time_s(self) -> float:
        """Controller time from the first move to home again (s)."""
        return self.end_time_s - self.start_time_s


class _Events:
    def event(self, kind: str, message: str) -> None:
        log.info("%s: %s", kind, message)


class SurveyCapture(Motion):
    """Runs a survey tour on ``client`` and detects the markers of ``cell`` with ``camera``."""

    def __init__(
        self,
        cell: CellConfig,
        survey_tour: SurveyTour,
        client: ControllerClient,
        camera: CameraBackend,
        stereo: StereoCalibration,
        settings: SurveyCaptureSettings | None = None,
        progress: Progress | None = None,
    ) -> None:
        self.survey_tour, self.client, self.camera, self.stereo = (
            survey_tour, client, camera, stereo)  # fmt: skip
        self.options = settings or SurveyCaptureSettings()
        self.store = _Events()
        self.progress = progress or (lambda event, data: None)
        self._loaded = None
        self._need_load = False
        T = cell.T_cell_part()
        self.codes = marker_codes(cell.reference_markers)
        self.geometry = {}
        for m in cell.reference_markers:
            p, n = marker_in_cell(m, T)
            self.geometry[m.id] = (p, n, 0.5 * m.diameter_m)

    def run(self) -> SurveyCaptures:
        """Visit every view, capture and detect; go home. A fault stops the arm and raises."""
        try:
            return self._run()
        except BaseException:
            self._safe_stop()
            raise

    def _run(self) -> SurveyCaptures:
        tour = self.survey_tour.tour
        wall = {"move_s": 0.0, "capture_s": 0.0, "wait_s": 0.0, "render_s": 0.0,
                "detect_s": 0.0, "cpu_s": 0.0}  # fmt: skip
        self._load(tour)
        t_start = self._call("status", self.client.status).time_s
        n = len(tour.stops)
        views: list[MarkerView] = []
        pool = executor(self.options.workers)
        try:
            pending: deque[Future] = deque()
            for k, stop in enumerate(tour.stops):
                t = time.perf_counter()
                self._move(k, f"survey view {stop.hole_id}")
                self._settled_status()
                wall["move_s"] += time.perf_counter() - t
                t = time.perf_counter()
                source, is_pair = pair_source(self.camera)
                wall["capture_s"] += time.perf_counter() - t
                pending.append(pool.submit(observe_view, source, self.stereo, self.codes,
                                           self.geometry, stop.hole_id,
                                           self.survey_tour.T_cell_left[stop.hole_id]))  # fmt: skip
                del source
                while pending and pending[0].done():  # in the tour's order
                    self._collect(views, pending.popleft(), n, wall)
                # pairs (not snapshots) wait in memory: the arm waits when too many do
                if is_pair and len(pending) > PAIRS_WAITING_PER_WORKER * max(
                    self.options.workers, 1
                ):
                    self._collect(views, pending.popleft(), n, wall)
            t = time.perf_counter()
            self._move(n, "home after the survey")
            t_end = self._call("status", self.client.status).time_s
            wall["move_s"] += time.perf_counter() - t
            t = time.perf_counter()
            while pending:
                self._collect(views, pending.popleft(), n, wall)
            wall["wait_s"] += time.perf_counter() - t
        finally:  # after a fault, the views not yet rendered or detected are dropped
            pool.shutdown(wait=True, cancel_futures=True)
        return SurveyCaptures(views, float(t_start), float(t_end), wall)

    def _collect(self, views: list[MarkerView], job: Future, n: int, wall: dict) -> None:
        view, times = job.result()
        for key, dt in times.items():
            wall[key] += dt
        views.append(view)
        self.progress("view", {"k": len(views), "n": n, "id": view.view_id,
                               "markers": len(view.both())})  # fmt: skip


def observe_view(
    source: PairSource,
    stereo: StereoCalibration,
    codes: Mapping[int, str],
    geometry: MarkerGeometry,
    view_id: str,
    T_cell_left_prior: np.ndarray,
) -> tuple[MarkerView, dict[str, float]]:
    """One view's markers (:func:`observe_pair`) from its pair, or from a snapshot that renders
    it (``source()``); and the wall time of the render and the detection and their CPU time (s)."""
    t, c = time.perf_counter(), time.thread_time()
    pair, was_rendered = rendered(source)
    render_s = time.perf_counter() - t if was_rendered else 0.0
    t = time.perf_counter()
    view = observe_pair(pair.left, pair.right, stereo, codes, geometry, view_id,
                        T_cell_left_prior)  # fmt: skip
    times = {"render_s": render_s, "detect_s": time.perf_counter() - t,
             "cpu_s": time.thread_time() - c}  # fmt: skip
    return view, times
