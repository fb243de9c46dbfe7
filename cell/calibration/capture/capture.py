"""Running a calibration tour: move to each view, settle, capture a stereo pair, record the
joints, detect the target in both images.

The arm moves with the run's own machinery (:class:`cell.link.motion.Motion`: load and reload
the trajectory, wait for "in position", reconnect within a budget, stop safely on a fault),
so a calibration tour survives a dead link exactly as a hole tour does. The joints recorded
for a view are the controller's report after the settle time, the ones the images were taken
at. Detection is :func:`measure.target.find_target` on the left and the right image, in worker
processes while the arm moves on (:mod:`cell.camera.workers`; the simulated head's renders
too): the views are collected in the tour's order, and a view's features depend only on its
images, so any number of workers gives the same views.
"""

from __future__ import annotations

import logging
import time
from collections import deque
from collections.abc import Callable
from concurrent.futures import Future
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from cell.calibration.capture.orient import orient_chessboard, refine_corners, repair_outliers
from cell.calibration.estimate.soft_views import is_soft
from cell.camera import CameraBackend
from cell.camera.backend import computing
from cell.camera.workers import (
    PAIRS_WAITING_PER_WORKER,
    PairSource,
    executor,
    pair_source,
    rendered,
)
from cell.link import messages as m
from cell.link.client import ControllerClient
from cell.link.motion import Motion
from measure import StereoCalibration
from measure.target import TargetSpec, find_target
from planner import Tour

log = logging.getLogger(__name__)

Array = NDArray[np.float64]

#: ``progress(event, data)``: "view" after each view (``k``, ``n``, ``id``, ``left``, ``right``:
#: whether the target was found), "solve" before the adjustment, "done" at the end
Progress = Callable[[str, dict], None]


@dataclass(frozen=True)
class CaptureSettings:
    """Motion and detection settings: wait after "in position" (s), longest move (s), how long
    a dead link is retried (s), widest accepted edge of a target image (px, 10-90 % rise);
    ``stop_on_unseen``: end the tour (home, then return the views so far) at the first view
    whose left or right image lacks the target, which the calibration refuses anyway (a view
    failing only a quality check is dropped instead, :mod:`cell.calibration.estimate.soft_views`,
    unless ``strict``); ``workers``: the processes that render (a simulated head) and detect
    while the arm moves on (0: this process, one view after another)."""

    settle_s: float = 0.2
    move_timeout_s: float = 120.0
    reconnect_budget_s: float = 15.0
    max_edge_width_px: float = 4.0
    stop_on_unseen: bool = True
    strict: bool = False
    workers: int = 2


@dataclass(frozen=True, eq=False)
class CapturedView:
    """One view of the tour: its id, the joints and controller time at the capture, the
    target's features in each image (px, ``None`` where not found) and why not."""

    id: str
    q_rad: Array
    time_s: float
    corners_left_px: Array | None
    corners_right_px: Array | None
    reason_left: str = ""
    reason_right: str = ""
    temperatures_c: Array | None = None


@dataclass(frozen=True, eq=False)
class TourCaptures:
    """Every view of one tour, the controller clock at the start and the end (s: the robot
    time) and the wall time of each step (s): ``move_s``, ``capture_s`` (the trigger, and the
    render when it is not deferred), ``wait_s`` (for the last detections after the tour); summed
    over the views wherever they ran: ``render_s`` (deferred renders), ``detect_s`` and
    ``cpu_s`` (the render's and the detection's CPU time)."""

    views: tuple[CapturedView, ...]
    start_time_s: float
    end_time_s: float
    wall_s: dict[str, float]

    @property
    def robot_time_s(self) -> float:
        """Controller time from the first move to home again (s)."""
        return self.end_time_s - self.start_time_s


class EventLog:
    """What the motion steps report (a dead link, a reload): kept in memory and logged."""

    def __init__(self) -> None:
        self.events: list[tuple[str, str]] = []

    def event(self, kind: str, message: str) -> None:
        """Record one event."""
        self.events.append((kind, message))
        log.info("%s: %s", kind, message)


class TourCapture(Motion):
    """Runs a calibration tour on ``client`` and captures with ``camera``."""

    def __init__(
        self,
        tour: Tour,
        client: ControllerClient,
        camera: CameraBackend,
        target: TargetSpec,
        settings: CaptureSettings | None = None,
        progress: Progress | None = None,
    ) -> None:
        self.tour, self.client, self.camera, self.target = tour, client, camera, target
        self.options = settings or CaptureSettings()
        self.store = EventLog()
        self.progress = progress or (lambda event, data: None)
        self._loaded: Tour | None = None
        self._need_load = False

    def run(self) -> TourCaptures:
        """Visit every view, capture and detect; go home. A fault stops the arm and raises."""
        try:
            return self._run()
        except BaseException:
            self._safe_stop()
            raise

    def _run(self) -> TourCaptures:
        wall = {"move_s": 0.0, "capture_s": 0.0, "wait_s": 0.0, "render_s": 0.0,
                "detect_s": 0.0, "cpu_s": 0.0}  # fmt: skip
        self._load(self.tour)
        t_start = self._call("status", self.client.status).time_s
        n = len(self.tour.stops)
        views: list[CapturedView] = []
        stop_early = self.options.stop_on_unseen
        workers = self.options.workers
        pool = executor(workers)
        try:
            pending: deque[tuple[str, m.Status, Future]] = deque()
            for k, stop in enumerate(self.tour.stops):
                t = time.perf_counter()
                self._move(k, f"calibration view {stop.hole_id}")
                st = self._settled_status()
                wall["move_s"] += time.perf_counter() - t
                t = time.perf_counter()
                source, is_pair = pair_source(self.camera)
                wall["capture_s"] += time.perf_counter() - t
                pending.append((stop.hole_id, st, pool.submit(
                    detect_view, source, self.target, self.camera.stereo,
                    self.options.max_edge_width_px)))  # fmt: skip
                del source
                while pending and pending[0][2].done():  # in the tour's order
                    self._collect(views, pending.popleft(), n, wall)
                # pairs (not snapshots) wait in memory: the arm waits when too many do
                if is_pair and len(pending) > PAIRS_WAITING_PER_WORKER * max(workers, 1):
                    self._collect(views, pending.popleft(), n, wall)
                if stop_early and _unseen(views, self.options.strict):
                    break
            t = time.perf_counter()
            self._move(n, "home after the calibration tour")
            t_end = self._call("status", self.client.status).time_s
            wall["move_s"] += time.perf_counter() - t
            t = time.perf_counter()
            while pending and not (stop_early and _unseen(views, self.options.strict)):
                self._collect(views, pending.popleft(), n, wall)
            wall["wait_s"] += time.perf_counter() - t
        finally:  # after a fault or an unseen target, the views not yet detected are dropped
            pool.shutdown(wait=True, cancel_futures=True)
        return TourCaptures(tuple(views), float(t_start), float(t_end), wall)

    def _collect(
        self, views: list[CapturedView], job: tuple[str, m.Status, Future], n: int, wall: dict
    ) -> None:
        """Append the view of a finished (or awaited) detection and report it."""
        vid, st, future = job
        with computing(self.camera):  # the arm waits for the detection
            (left, why_left), (right, why_right), times = future.result()
        for key, dt in times.items():
            wall[key] += dt
        q = np.asarray(st.q_rad, float).copy()
        temps = np.asarray(st.temperatures_c, float).copy()  # the arm's warming (warming.py)
        views.append(CapturedView(vid, q, float(st.time_s), left, right, why_left, why_right,
                                  temps))  # fmt: skip
        self.progress("view", {"k": len(views) - 1, "n": n, "id": vid,
                               "left": left is not None, "right": right is not None})  # fmt: skip


def detect_target(
    image: np.ndarray, target: TargetSpec, K: Array, dist: Array, max_edge_width_px: float
) -> tuple[Array | None, str]:
    """The target's features in one image in the board's order (:mod:`.orient`), refined, a
    corner off the plate's plane refined again (``K``, ``dist``: that camera's intrinsics); or
    why not found."""
    det = find_target(image, target, max_edge_width_px)
    if det.points is None:
        return None, det.reason
    pts = orient_chessboard(image, det.points, target)
    pts = refine_corners(image, pts, target)
    if target.kind != "chessboard":
        return pts, ""
    pts, why = repair_outliers(image, pts, target, K, dist)
    return (None, why) if why else (pts, "")


def detect_view(
    source: PairSource, target: TargetSpec, stereo: StereoCalibration, max_edge_width_px: float
) -> tuple[tuple[Array | None, str], tuple[Array | None, str], dict[str, float]]:
    """Both images' features (or why not) from a view's pair, or from a snapshot that renders
    it; and the wall time of the render and the detection and their CPU time (s). Runs in a
    worker process."""
    t, c = time.perf_counter(), time.thread_time()
    pair, was_rendered = rendered(source)
    render_s = time.perf_counter() - t if was_rendered else 0.0
    t = time.perf_counter()
    left = detect_target(pair.left, target, stereo.K_left, stereo.dist_left, max_edge_width_px)
    right = detect_target(pair.right, target, stereo.K_right, stereo.dist_right,
                          max_edge_width_px)  # fmt: skip
    times = {"render_s": render_s, "detect_s": time.perf_counter() - t,
             "cpu_s": time.thread_time() - c}  # fmt: skip
    return left, right, times


def _unseen(views: list[CapturedView], strict: bool) -> bool:
    """Whether the last view lacks the target in an image (for another reason than a quality
    check, unless ``strict``)."""
    if not views:
        return False
    v = views[-1]
    return any(pts is None and (strict or not is_soft(why))
               for pts, why in ((v.corners_left_px, v.reason_left),
                                (v.corners_right_px, v.reason_right)))  # fmt: skip
