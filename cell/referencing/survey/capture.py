"""Running the survey tour: move to each view, settle, capture a stereo pair, detect and
identify the markers in both images (:func:`cell.referencing.detection.observe_pair`).

The arm moves with the run's machinery (:class:`cell.link.motion.Motion`: reload, reconnect
within a budget, stop safely on a fault). Each view's prior is its planned left-camera pose
(the arm's idea of it): it removes the perspective bias of the markers' centres and starts the
adjustment. A view's detection runs while the arm moves on (OpenCV releases the GIL).
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass, field

from cell.camera import CameraBackend
from cell.config import CellConfig
from cell.config.markers import marker_codes, marker_in_cell
from cell.link.client import ControllerClient
from cell.link.motion import Motion
from cell.referencing.detection import observe_pair
from cell.referencing.observations import MarkerView
from cell.referencing.survey.tour import SurveyTour
from measure import StereoCalibration

log = logging.getLogger(__name__)

#: ``progress(event, data)``: "view" after each view (``k``, ``n``, ``id``, ``markers``)
Progress = Callable[[str, dict], None]


@dataclass(frozen=True)
class SurveyCaptureSettings:
    """Wait after "in position" (s), longest move (s), how long a dead link is retried (s)."""

    settle_s: float = 0.2
    move_timeout_s: float = 120.0
    reconnect_budget_s: float = 15.0


@dataclass
class SurveyCaptures:
    """Every view's markers, the controller clock at the start and the end (s) and the wall
    time of each step (s)."""

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

    def _observe(self, vid: str, pair) -> tuple[MarkerView, float]:
        t = time.perf_counter()
        view = observe_pair(pair.left, pair.right, self.stereo, self.codes, self.geometry, vid,
                            self.survey_tour.T_cell_left[vid])  # fmt: skip
        return view, time.perf_counter() - t

    def _run(self) -> SurveyCaptures:
        tour = self.survey_tour.tour
        wall = {"move_s": 0.0, "capture_s": 0.0, "detect_s": 0.0}
        self._load(tour)
        t_start = self._call("status", self.client.status).time_s
        n = len(tour.stops)
        views: list[MarkerView] = []
        with ThreadPoolExecutor(max_workers=1) as pool:
            pending: list[Future] = []
            for k, stop in enumerate(tour.stops):
                t = time.perf_counter()
                self._move(k, f"survey view {stop.hole_id}")
                self._settled_status()
                wall["move_s"] += time.perf_counter() - t
                t = time.perf_counter()
                pair = self.camera.capture()
                wall["capture_s"] += time.perf_counter() - t
                if pending:
                    self._collect(views, pending.pop(), n, wall)
                pending.append(pool.submit(self._observe, stop.hole_id, pair))
                del pair
            t = time.perf_counter()
            self._move(n, "home after the survey")
            t_end = self._call("status", self.client.status).time_s
            wall["move_s"] += time.perf_counter() - t
            if pending:
                self._collect(views, pending.pop(), n, wall)
        return SurveyCaptures(views, float(t_start), float(t_end), wall)

    def _collect(self, views: list[MarkerView], job: Future, n: int, wall: dict) -> None:
        view, dt = job.result()
        wall["detect_s"] += dt
        views.append(view)
        self.progress("view", {"k": len(views), "n": n, "id": view.view_id,
                               "markers": len(view.both())})  # fmt: skip
