"""Reliability: a faulty line with a disconnect, and a runner killed at a random point then
resumed; in both, every hole is measured exactly once and nothing stored is lost."""

from __future__ import annotations

import os
import random
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from cell_fixtures import SmallCell, link_for, steady_drift

from cell.link.client import ControllerClient, LinkOptions
from cell.review.store import Store, count_measurements
from cell.run.runner import Runner, RunOptions
from cell.run.setup import start_run
from cell.sim.camserver import CameraServer
from cell.sim.faults import FaultPlan
from cell.sim.rapid_controller import RapidController
from cell.sim.session import SimCell
from cell.sim.world import WorldOptions


def _inprocess_run(sc: SmallCell, run_dir: Path, sim: SimCell, link: LinkOptions):
    files = start_run(run_dir, sc.cell, sc.tour, "tour.json", sim.url)
    ctrl = "rapid" if isinstance(sim.controller, RapidController) else "python"
    client = ControllerClient(sim.url, link_for(ctrl, link))
    client.connect()
    options = RunOptions(settle_s=0.0, reference_rounds=0, reconnect_budget_s=10.0)
    try:
        result = Runner(files.cell, files.tour, files.store, client, sim.camera, options).run()
        return result, files.store.results(), files.store.events()
    finally:
        client.close()
        files.store.close()


@pytest.mark.parametrize("transport", ["pty", "socket"])
def test_dropped_corrupted_frames_and_a_disconnect(
    small_cell: SmallCell, tmp_path: Path, controller: str, transport: str
) -> None:
    link = LinkOptions(response_timeout_s=0.04, retries=8, heartbeat_period_s=0.1)
    # the outage swallows every attempt of the request it meets, however slowly the simulated
    # controller reads them: the client must give up and reconnect (not a race with the clock)
    faults = FaultPlan(drop=0.05, corrupt=0.02, disconnect_after=50, disconnect_s=1.5,
                       disconnect_frames=link.retries + 1, seed=7)  # fmt: skip
    world = WorldOptions(speed=20.0, drift=steady_drift())
    with SimCell.start(small_cell.cell, world, faults, transport,
                       controller=controller) as sim:  # fmt: skip
        result, stored, events = _inprocess_run(small_cell, tmp_path, sim, link)
        server = sim.server
    assert result.status == "done"
    assert [r.hole_id for r in stored] == small_cell.tour.hole_order
    assert all(r.status == "ok" for r in stored)
    assert server.disconnects == 1, server.requests
    assert server.dropped > 0 and server.corrupted > 0
    assert result.link["retransmits"] > 0 and result.link["reconnects"] >= 1
    assert any(e["kind"] == "link" and "restored" in e["message"] for e in events)


def _holecell(*args: str) -> subprocess.Popen:
    env = dict(os.environ, PYTHONUNBUFFERED="1")
    cmd = [sys.executable, "-m", "cell.cli", *args]
    return subprocess.Popen(cmd, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT)


def test_killed_runner_resumes_to_the_same_store(
    small_cell: SmallCell, tmp_path: Path, controller_rapid_slow: str
) -> None:
    world = WorldOptions(speed=20.0, drift=steady_drift())
    link = LinkOptions(response_timeout_s=0.05)
    with SimCell.start(small_cell.cell, world, controller=controller_rapid_slow) as sim:
        clean, reference, _ = _inprocess_run(small_cell, tmp_path / "uninterrupted", sim, link)
    rng = random.Random(int(os.environ.get("HOLECELL_KILL_SEED", "3")))
    run_dir = tmp_path / "killed"
    with (
        SimCell.start(small_cell.cell, world, controller=controller_rapid_slow) as sim,
        CameraServer(sim.camera).start() as cam,
    ):
        common = ["--port", sim.url, "--camera", cam.url, "--settle-s", "0", "--quiet"]
        first = _holecell(
            "run",
            str(small_cell.tour_path),
            "--cell",
            str(small_cell.path),
            "--out",
            str(run_dir),
            "--reference-rounds",
            "0",
            "--yes",
            *common,
        )
        # a random point inside the run: after k holes are stored, part way into the next
        k = rng.randrange(len(reference))
        while count_measurements(run_dir) < k and first.poll() is None:
            time.sleep(0.005)
        time.sleep(rng.uniform(0.0, 0.5 * clean.timings["run_s"] / len(reference)))
        first.send_signal(signal.SIGKILL)
        first.wait()
        with Store.open(run_dir) as store:
            n_before = len(store.stored_ids())
        second = _holecell("run", "--resume", str(run_dir), "--yes", *common)
        out, _ = second.communicate(timeout=120)
        assert second.returncode == 0, out.decode()  # fmt: skip
    with Store.open(run_dir) as store:
        resumed = store.results()
    assert n_before < len(reference)
    assert [r.hole_id for r in resumed] == [r.hole_id for r in reference]
    for a, b in zip(resumed, reference, strict=True):
        assert a.status == b.status
        np.testing.assert_allclose(a.center_part_m, b.center_part_m, atol=1e-9)
        assert abs(a.diameter_m - b.diameter_m) < 1e-9
