"""Running a calibration tour: move to each view, settle, capture a stereo pair, record the
joints, detect the target in both images.

The arm moves with the run's own machinery (:class:`cell.link.motion.Motion`: load and reload
the trajectory, wait for "in position", reconnect within a budget, stop safely on a fault),
so a calibration tour survives a dead link exactly as a hole tour does. The joints recorded
for a view are the controller's report after the settle time, the ones the images were taken
at. Detection is :func:`measure.target.find_target` on the left and the right image.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from cell.calibration.capture.orient import orient_chessboard, refine_corners, repair_outliers
from cell.calibration.estimate.soft_views import is_soft
from cell.camera import CameraBackend
from cell.camera.backend import computing
from cell.link import messages as m
from cell.link.client import ControllerClient
from cell.link.motion import Motion
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
    unless ``strict``)."""

    settle_s: float = 0.2
    move_timeout_s: float = 120.0
    reconnect_budget_s: float = 15.0
    max_edge_width_px: float = 4.0
    stop_on_unseen: bool = True
    strict: bool = False


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
    time) and the wall time of each step (s)."""

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

    def _detect(self, image: np.ndarray, side: str) -> tuple[Array | None, str]:
        """The target's features in the board's order (:mod:`.orient`), refined, a corner off
        the plate's plane refined again; or why not found."""
        det = find_target(image, self.target, self.options.max_edge_width_px)
        if det.points is None:
            return None, det.reason
        pts = orient_chessboard(image, det.points, self.target)
        pts = refine_corners(image, pts, self.target)
        if self.target.kind != "chessboard":
            return pts, ""
        st = self.camera.stereo
        K, dist = (st.K_left, st.dist_left) if side == "left" else (st.K_right, st.dist_right)
        pts, why = repair_outliers(image, pts, self.target, K, dist)
        return (None, why) if why else (pts, "")

    def _detect_pair(
        self, pair
    ) -> tuple[tuple[Array | None, str], tuple[Array | None, str], float]:
        """Both images' features (or why not) and the wall time the detection took (s)."""
        t = time.perf_counter()
        left, right = self._detect(pair.left, "left"), self._detect(pair.right, "right")
        return left, right, time.perf_counter() - t

    def _run(self) -> TourCaptures:
        wall = {"move_s": 0.0, "capture_s": 0.0, "detect_s": 0.0}
        self._load(self.tour)
        t_start = self._call("status", self.client.status).time_s
        n = len(self.tour.stops)
        views: list[CapturedView] = []
        # a view's detection runs while the arm moves on to the next one (OpenCV releases the
        # GIL): the robot does not wait for the computer; at most one pair waits in memory
        stop_early = self.options.stop_on_unseen
        with ThreadPoolExecutor(max_workers=1) as pool:
            pending: list[tuple[str, m.Status, Future]] = []
            for k, stop in enumerate(self.tour.stops):
                t = time.perf_counter()
                self._move(k, f"calibration view {stop.hole_id}")
                st = self._settled_status()
                wall["move_s"] += time.perf_counter() - t
                t = time.perf_counter()
                pair = self.camera.capture()
                wall["capture_s"] += time.perf_counter() - t
                if pending:  # the previous view's detection, done during this move
                    self._collect(views, pending.pop(), n, wall)
                if stop_early and _unseen(views, self.options.strict):
                    break
                pending.append((stop.hole_id, st, pool.submit(self._detect_pair, pair)))
                del pair
            t = time.perf_counter()
            self._move(n, "home after the calibration tour")
            t_end = self._call("status", self.client.status).time_s
            wall["move_s"] += time.perf_counter() - t
            if pending:
                self._collect(views, pending.pop(), n, wall)
        return TourCaptures(tuple(views), float(t_start), float(t_end), wall)

    def _collect(
        self, views: list[CapturedView], job: tuple[str, m.Status, Future], n: int, wall: dict
    ) -> None:
        """Append the view of a finished (or awaited) detection and report it."""
        vid, st, future = job
        with computing(self.camera):  # the arm waits at its view for the detection
            (left, why_left), (right, why_right), dt = future.result()
        wall["detect_s"] += dt
        q = np.asarray(st.q_rad, float).copy()
        temps = np.asarray(st.temperatures_c, float).copy()  # the arm's warming (warming.py)
        views.append(CapturedView(vid, q, float(st.time_s), left, right, why_left, why_right,
                                  temps))  # fmt: skip
        self.progress("view", {"k": len(views) - 1, "n": n, "id": vid,
                               "left": left is not None, "right": right is not None})  # fmt: skip


def _unseen(views: list[CapturedView], strict: bool) -> bool:
    """Whether the last view lacks the target in an image (for another reason than a quality
    check, unless ``strict``)."""
    if not views:
        return False
    v = views[-1]
    return any(pts is None and (strict or not is_soft(why))
               for pts, why in ((v.corners_left_px, v.reason_left),
                                (v.corners_right_px, v.reason_right)))  # fmt: skip
