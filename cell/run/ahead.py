"""A stop's pair on its way while the computer works on the stop before.

The runner captures stop ``k`` and then, with the arm waiting at ``k``, measures stop ``k - 1``:
a real head's pair is already there; the simulated head's snapshot (:mod:`cell.camera.workers`)
is rendered in a worker process meanwhile, and kept in the run directory there too, so that the
cell computer's two cores render one stop and measure another. Each stop is still measured from
its own pair, in the tour's order, so the results are those of one stop after another.
"""

from __future__ import annotations

import time
from concurrent.futures import Executor, Future
from pathlib import Path

from cell.camera import CameraBackend, StereoPair
from cell.camera.errors import PairError
from cell.camera.workers import InProcess, PairSource, executor, pair_source, rendered
from cell.review.audit_images import save_pair


class PairsAhead:
    """Captures of ``camera`` whose pairs come later: rendered in the process's pool of
    ``workers`` processes (:func:`cell.camera.workers.executor`) when the camera takes
    snapshots, one stop ahead; ``keep_dir``: the run directory the pairs are kept in (None:
    none kept)."""

    def __init__(self, camera: CameraBackend, keep_dir: Path | None, workers: int = 2) -> None:
        self.camera, self.keep_dir = camera, keep_dir
        snapshots = getattr(camera, "snapshot", None) is not None
        self._pool: Executor = executor(workers) if snapshots else InProcess()

    def capture(self, stop_index: int, hole_id: str, keep: bool = True) -> Future:
        """Trigger the head now; the future gives ``(pair, kept)``: the pair, and whether it
        was kept already (``stop_index``, ``hole_id``: its file names), or raises the camera's
        :class:`PairError`."""
        future: Future = Future()
        try:
            source, is_pair = pair_source(self.camera)
        except PairError as exc:
            future.set_exception(exc)
            return future
        if is_pair:
            future.set_result((source, False))
            return future
        keep_dir = self.keep_dir if keep else None
        return self._pool.submit(render_and_keep, source, keep_dir, stop_index, hole_id)

    def close(self) -> None:
        """Drop a capture not yet rendered (the process's workers stay for the next user)."""
        self._pool.shutdown(wait=True, cancel_futures=True)


def render_and_keep(
    source: PairSource, keep_dir: Path | None, stop_index: int, hole_id: str
) -> tuple[StereoPair, bool]:
    """The pair of ``source``, kept in ``keep_dir`` when given; and whether it was kept. Runs
    in a worker process."""
    pair, _ = rendered(source)
    if keep_dir is None:
        return pair, False
    save_pair(keep_dir, stop_index, hole_id, pair.left, pair.right)
    return pair, True


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
