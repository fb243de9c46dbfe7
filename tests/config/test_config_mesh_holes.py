"""Mesh obstacles, holes from a CSV and clearance in the cell file (meshes made in the test)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import trimesh
import yaml

from cell.config import builtin_cell_path, load_cell
from cell.errors import ConfigError
from robots import Arm, Shape

BUILTIN = yaml.safe_load(builtin_cell_path().read_text())


def _write_cell(tmp_path: Path, **changes: object) -> Path:
    data = yaml.safe_load(yaml.safe_dump(BUILTIN))
    for dotted, value in changes.items():
        node = data
        *parents, last = dotted.split("__")
        for key in parents:
            node = node[key]
        node[last] = value
    path = tmp_path / "cell.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


@pytest.mark.parametrize("suffix", ["stl", "obj", "ply"])
def test_mesh_obstacle_checks_like_the_box_it_was_made_from(tmp_path: Path, suffix: str) -> None:
    # a 0.3 m cube exported in millimetres, placed in the cell with scale 0.001
    trimesh.creation.box(extents=(300.0, 300.0, 300.0)).export(tmp_path / f"block.{suffix}")
    pose = {"xyz": [0.0, -0.8, 1.0], "rpy": [0.0, 0.0, 0.3]}
    mesh_obstacle = {"name": "block", "mesh": {"path": f"block.{suffix}", "scale": 0.001}}
    cfg = load_cell(_write_cell(tmp_path, environment__obstacles=[{**mesh_obstacle, "pose": pose}]))
    (shape,) = cfg.obstacle_shapes()[-1:]
    assert shape.kind == "mesh" and np.allclose(np.ptp(shape.mesh.vertices, axis=0), 0.3)
    arm_mesh = cfg.build_arm()
    arm_box = Arm(cfg.robot.model, T_cell_base=cfg.T_cell_base())
    arm_box.set_tool(cfg.T_tool0_tcp(), cfg.tool_shapes())
    others = cfg.obstacle_shapes()[:-1]
    arm_box.add_obstacles([*others, Shape("box", (0.3, 0.3, 0.3), shape.T, "block")])
    arm_box.set_clearance(cfg.robot.clearance_m, cfg.tool.clearance_m)
    rng = np.random.default_rng(3)
    verdicts = []
    for _ in range(150):
        q = rng.uniform(arm_box.lower, arm_box.upper) * 0.6
        verdicts.append(arm_box.in_collision(q))
        assert arm_mesh.in_collision(q) == verdicts[-1]
    assert any(verdicts) and not all(verdicts)


def test_missing_and_empty_meshes_are_refused_naming_field_and_path(tmp_path: Path) -> None:
    ob = [{"mesh": {"path": "nowhere.stl", "scale": 0.001}}]
    with pytest.raises(ConfigError) as err:
        load_cell(_write_cell(tmp_path, part__obstacles=ob))
    assert "part.obstacles[0].mesh.path" in str(err.value)
    assert "nowhere.stl" in str(err.value) and "no such file" in str(err.value)
    (tmp_path / "empty.stl").write_text("solid empty\nendsolid empty\n")
    ob = [{"mesh": {"path": "empty.stl"}}]
    with pytest.raises(ConfigError) as err:
        load_cell(_write_cell(tmp_path, environment__obstacles=ob))
    assert "environment.obstacles[0].mesh.path" in str(err.value)
    assert "empty.stl" in str(err.value)
    (tmp_path / "noise.stl").write_bytes(np.random.default_rng(0).bytes(3000))
    ob = [{"mesh": {"path": "noise.stl"}}]
    with pytest.raises(ConfigError) as err:
        load_cell(_write_cell(tmp_path, environment__obstacles=ob))
    assert "environment.obstacles[0].mesh.path" in str(err.value)
    assert "noise.stl" in str(err.value)


HEADER = "id,x_mm,y_mm,z_mm,nx,ny,nz,diameter_mm,tolerance_um\n"


def test_holes_csv_adds_holes_in_metres(tmp_path: Path) -> None:
    (tmp_path / "holes.csv").write_text(
        HEADER + "CSV1,419.2,107.1,401,0,0,1,6,50\nCSV2,0,0,500,0,0,1,8,\n"
    )
    cfg = load_cell(_write_cell(tmp_path, part__holes_csv="holes.csv"))
    holes = {h.id: h for h in cfg.part.holes}
    assert len(cfg.part.holes) == len(BUILTIN["part"]["holes"]) + 2
    assert np.allclose(holes["CSV1"].position, [0.4192, 0.1071, 0.401])
    assert holes["CSV1"].diameter == pytest.approx(0.006)
    assert holes["CSV1"].tolerance == pytest.approx(5e-5)
    assert holes["CSV2"].tolerance is None


@pytest.mark.parametrize(
    ("text", "expect"),
    [
        (HEADER.replace("x_mm", "x_in") + "A,1,2,3,0,0,1,6,50\n", "row 1, column 'x_in'"),
        (HEADER.replace("diameter_mm", "diameter") + "A,1,2,3,0,0,1,6,50\n", "'diameter'"),
        (HEADER + "A,1,2,3,0,0,1,6,50\nB,1,two,3,0,0,1,6,50\n", "row 3, column 'y_mm'"),
        (HEADER + "A,1,2,3,0,0,2,6,50\n", "row 2, columns nx, ny, nz"),
        ("id,x_mm,y_mm,z_mm,nx,ny,nz\nA,1,2,3,0,0,1\n", "missing columns ['diameter']"),
        (HEADER + "A,1,2,3,0,0,1,6,50\nA,1,2,3,0,0,1,6,50\n", "row 3, column 'id'"),
        (HEADER + "SPL1,1,2,3,0,0,1,6,50\n", "row 2, column 'id'"),
    ],
)
def test_holes_csv_errors_name_file_row_and_column(tmp_path: Path, text: str, expect: str) -> None:
    (tmp_path / "holes.csv").write_text(text)
    with pytest.raises(ConfigError) as err:
        load_cell(_write_cell(tmp_path, part__holes_csv="holes.csv"))
    assert "holes.csv" in str(err.value) and expect in str(err.value)


def test_clearance_changes_the_verdict_and_is_shown(tmp_path: Path) -> None:
    arm = Arm()
    q = np.array([0.0, 0.0, 0.0, 0.0, 0.0, 0.0])
    # a sphere 7 mm above the forearm's top face (link_4 box top at z = 1.26 + 0.078)
    T = np.eye(4)
    T[:3, 3] = [0.55, 0.0, 1.26 + 0.078 + 0.05 + 0.007]
    arm.add_obstacles([Shape("sphere", (0.05,), T, "ball")])
    assert not arm.in_collision(q)
    arm.set_clearance(0.010, 0.005)
    assert arm.in_collision(q)
    assert arm.collision.in_collision_exhaustive(q)
    arm.set_clearance(0.005, 0.005)
    assert not arm.in_collision(q)


def test_broad_phase_agrees_with_every_pair_under_clearance() -> None:
    cfg = load_cell(builtin_cell_path())
    arm = cfg.build_arm()
    assert cfg.robot.clearance_m == 0.010 and cfg.tool.clearance_m == 0.005
    rng = np.random.default_rng(7)
    hits = 0
    for _ in range(300):
        q = rng.uniform(arm.lower, arm.upper)
        hit = arm.in_collision(q)
        hits += hit
        assert hit == arm.collision.in_collision_exhaustive(q)
    assert 0 < hits < 300
