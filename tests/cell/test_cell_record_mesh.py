"""A mesh obstacle is logged to the Rerun recording as a mesh (the mesh made in the test)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import rerun as rr
import rerun.chunk as rrc
import trimesh

from cell.review.recording import Recorder
from robots import Shape
from robots.meshes import load_mesh


def test_mesh_obstacle_is_logged_as_mesh3d(tmp_path: Path) -> None:
    trimesh.creation.icosphere(subdivisions=2, radius=50.0).export(tmp_path / "ball.ply")
    mesh = load_mesh(tmp_path / "ball.ply", scale=0.001)
    T = np.eye(4)
    T[:3, 3] = [1.0, 0.2, 0.5]
    rrd = tmp_path / "scene.rrd"
    recorder = object.__new__(Recorder)  # only the scene logging, no run
    recorder.rec = rr.RecordingStream("holecell-test")
    recorder.rec.set_sinks(rr.FileSink(str(rrd)))
    recorder.T_view_cell = np.eye(4)
    recorder._shape("cell/obstacles/0_ball", Shape("mesh", (), T, "ball", mesh))
    recorder.rec.flush()
    recorder.rec.disconnect()
    chunks = [
        ch for ch in rrc.RrdReader(rrd).stream() if str(ch.entity_path) == "/cell/obstacles/0_ball"
    ]
    assert chunks
    table = chunks[0].to_record_batch()
    names = " ".join(table.schema.names)
    assert "Mesh3D" in names and "vertex_positions" in names
