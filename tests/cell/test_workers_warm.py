"""The process's workers started ahead (:func:`cell.camera.workers.start_workers`): each runs the
warm-up before its first job, single-threaded; a warm-up that fails leaves working workers; the
demo's warm-up renders and detects with a simulated head."""

from __future__ import annotations

import os
from functools import partial
from pathlib import Path

import pytest

from cell.camera import workers
from cell.camera.workers import start_workers
from cell.demo.warm import warm_sim_worker
from measure.synth import RenderOptions, standard_stereo, texture
from measure.target import TargetSpec

#: the pool size of these tests (no other user: a pool of its own)
SIZE = 3


def _warm(folder: str) -> None:
    Path(folder, f"warm-{os.getpid()}").touch()


def _fail() -> None:
    raise RuntimeError("no texture today")


def _job(folder: str) -> tuple[int, bool, int]:
    import cv2

    return os.getpid(), Path(folder, f"warm-{os.getpid()}").is_file(), cv2.getNumThreads()


@pytest.fixture()
def own_pool():
    """No pool of :data:`SIZE` before the test, and none after it."""
    pool = workers._POOLS.pop(SIZE, None)
    if pool is not None:
        pool.shutdown()
    yield
    pool = workers._POOLS.pop(SIZE, None)
    if pool is not None:
        pool.shutdown()


def test_every_worker_warms_before_its_first_job(own_pool, tmp_path: Path) -> None:
    assert start_workers(SIZE, partial(_warm, str(tmp_path)))
    assert not start_workers(SIZE, partial(_warm, str(tmp_path)))  # it runs already
    pool = workers.executor(SIZE)
    results = [f.result() for f in [pool.submit(_job, str(tmp_path)) for _ in range(12)]]
    assert all(warm for _, warm, _ in results)
    assert all(threads == 1 for _, _, threads in results)
    pool.shutdown()


def test_a_failed_warm_up_leaves_working_workers(own_pool, tmp_path: Path) -> None:
    assert start_workers(SIZE, _fail)
    pool = workers.executor(SIZE)
    assert pool.submit(sum, (1, 2)).result() == 3
    pool.shutdown()


def test_the_demo_warm_up_renders_and_detects() -> None:
    warm_sim_worker(standard_stereo(), TargetSpec("chessboard", 9, 6, 0.009), RenderOptions())
    assert texture.texture_tile.cache_info().currsize == 1  # a hole scene was rendered
