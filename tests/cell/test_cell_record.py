"""The Rerun recording of a run holds the robot, the scene, each pair with its edges and
ellipse, the 3D circle, the time series, the run state and a default blueprint."""

from __future__ import annotations

from pathlib import Path

import rerun.chunk as rrc
from cell_fixtures import SmallCell, steady_drift

from cell.link.client import ControllerClient
from cell.review.recording import Recorder
from cell.run.runner import Runner, RunOptions
from cell.run.setup import start_run
from cell.sim.session import SimCell
from cell.sim.world import WorldOptions


def test_run_recording(small_cell: SmallCell, tmp_path: Path) -> None:
    rrd = tmp_path / "run.rrd"
    world = WorldOptions(speed=20.0, drift=steady_drift())
    with SimCell.start(small_cell.cell, world) as sim:
        files = start_run(tmp_path, small_cell.cell, small_cell.tour, "tour", sim.url)
        rec = Recorder.create(rrd, small_cell.cell, small_cell.tour)
        with ControllerClient(sim.url) as client:
            Runner(small_cell.cell, small_cell.tour, files.store, client, sim.camera,
                   RunOptions(settle_s=0.0, reference_rounds=0), recorder=rec).run()  # fmt: skip
        rec.close()
        files.store.close()
    reader = rrc.RrdReader(rrd)
    assert len(reader.blueprints()) == 1 and len(reader.recordings()) == 1
    paths = {str(ch.entity_path) for ch in reader.stream()}
    model = small_cell.cell.robot.model
    expected = {
        "/transforms", "/tour/path", "/tour/stops", "/cell/holes", "/run/tcp", "/run/state",
        "/run/hole/points", "/run/hole/circle", "/camera/left/image", "/camera/left/edges",
        "/camera/left/ellipse", "/camera/right/image", "/plots/deviation/position",
        "/plots/deviation/diameter", "/plots/temperature/s1",
    }  # fmt: skip
    assert expected <= paths, expected - paths
    assert any(p.startswith(f"/{model}/visual_geometries/link_6") for p in paths)
    assert any(p.startswith("/cell/obstacles/") for p in paths)
