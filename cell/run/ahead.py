"""Stops' pairs on their way while the computer works on an earlier stop.

The runner captures stop ``k`` and then, with the arm waiting at ``k``, measures stop
``k - STOPS_AHEAD``: a real head's pairs are already there; the simulated head's snapshots
(:mod:`cell.camera.workers`) are rendered in worker processes meanwhile, kept in the run
directory and their markers detected there too, so that the cell computer's two cores render
and measure at once. Each stop is still measured from its own pair, in the tour's order, so the
results are those of one stop after another.
"""

from __future__ import annotations

import time
from collections.abc import Mapping
from concurrent.futures import Executor, Future
from pathlib import Path

from cell.camera import CameraBackend, StereoPair
from cell.camera.errors import PairError
from cell.camera.workers import InProcess, PairSource, executor, pair_source, rendered
from cell.referencing.detection import Detections, detect_pair
from cell.review.audit_images import save_pair
from measure import StereoCalibration

#: the stops captured ahead of the one being measured: the arm waits at stop ``k`` while the
#: computer measures stop ``k - STOPS_AHEAD`` and the workers render the ones between (a pair
#: per core: the cell computer's two)
STOPS_AHEAD = 2


class PairsAhead:
    """Captures of ``camera`` whose pairs come later: rendered in the process's pool of
    ``workers`` processes (:func:`cell.camera.workers.executor`) when the camera takes
    snapshots, :data:`STOPS_AHEAD` stops ahead; ``keep_dir``: the run directory the pairs are
    kept in (None: none kept); ``markers``: the head and the marker codes to find in each
    rendered pair."""

    def __init__(
        self, camera: CameraBackend, keep_dir: Path | None, workers: int = 2,
        markers: tuple[StereoCalibration, Mapping[int, str]] | None = None,
    ) -> None:  # fmt: skip
        self.camera, self.keep_dir = camera, keep_dir
        self.markers = (markers[0], dict(markers[1])) if markers and markers[1] else None
        snapshots = getattr(camera, "snapshot", None) is not None
        self._pool: Executor = executor(workers) if snapshots else InProcess()

    def capture(self, stop_index: int, hole_id: str, keep: bool = True) -> Future:
        """Trigger the head now; the future gives ``(pair, kept, detections)``: the pair,
        whether it was kept already (``stop_index``, ``hole_id``: its file names) and the
        markers found in it (:func:`cell.referencing.detection.detect_pair`; None: not looked
        for, as with a camera's own pair, which the caller detects), or raises the camera's
        :class:`PairError`."""
        future: Future = Future()
        try:
            source, is_pair = pair_source(self.camera)
        except PairError as exc:
            future.set_exception(exc)
            return future
        if is_pair:
            future.set_result((source, False, None))
            return future
        keep_dir = self.keep_dir if keep else None
        return self._pool.submit(render_and_keep, source, keep_dir, stop_index, hole_id,
                                 self.markers)  # fmt: skip

    def close(self) -> None:
        """Drop a capture not yet rendered (the process's workers stay for the next user)."""
        self._pool.shutdown(wait=True, cancel_futures=True)


def render_and_keep(
    source: PairSource, keep_dir: Path | None, stop_index: int, hole_id: str,
    markers: tuple[StereoCalibration, Mapping[int, str]] | None = None,
) -> tuple[StereoPair, bool, Detections | None]:  # fmt: skip
    """The pair of ``source``, kept in ``keep_dir`` when given; whether it was kept; and with
    ``markers`` (the head, the codes) the markers found in it. Runs in a worker process."""
    pair, _ = rendered(source)
    dets = None if markers is None else detect_pair(pair.left, pair.right, *markers)
    if keep_dir is None:
        return pair, False, dets
    save_pair(keep_dir, stop_index, hole_id, pair.left, pair.right)
    return pair, True, dets


class Laps:
    """The wall time of each step of a stop (s), lap by lap."""

    def __init__(self) -> None:
        self.laps: dict[str, float] = {}
        self._t = time.perf_counter()

    def lap(self, name: str) -> None:
        t = time.perf_counter()
        self.laps[name], self._t = t - self._t, t

    def skip(self) -> None:
        """Start the next lap now: the time since the last one is nobody's."""
        self._t = time.perf_counter()
