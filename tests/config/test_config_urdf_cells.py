"""Cell files whose robot.model is a URDF path: paths, package_paths, limits, errors."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from cell.cli import main
from cell.commands.thermal_cmd import _table_of
from cell.config import load_cell
from cell.errors import ConfigError
from robots import dh_table
from robots.urdf_writer import URDF_DIR

sys.path.insert(0, str(Path(__file__).parents[1] / "robots"))
from urdf_factory import KUKA_LIKE, write_stl, write_urdf

CELL = """
name: urdf-cell
robot:
  model: {model}
  package_paths: {package_paths}
  home: [0, -0.3, 0.3, 0, 1.2, 0]
  limits:
    velocity_scale: 1.0
    position: {position}
tool: {{tool0_to_tcp: {{xyz: [0, 0, 0.15], rpy: [0, 0, 0]}}, standoff_m: 0.25}}
part:
  base: {{xyz: [1.0, 0, 0.5], rpy: [0, 0, 0]}}
  holes: [{{id: H1, position: [0, 0, 0], normal: [0, 0, 1], diameter: 0.01}}]
reference_targets:
  - {{id: R1, position: [0.9, -0.5, 0.3], normal: [0, 0, 1], diameter: 0.010}}
"""


def _write_cell(folder: Path, model: str, package_paths: str = "[]", position: str = "null"):
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / "cell.yaml"
    path.write_text(CELL.format(model=model, package_paths=package_paths, position=position))
    return path


def _kuka_with_meshes(root: Path) -> None:
    """A KUKA-like URDF under root/robot, its meshes in the package root/pkgs/kuka_like."""
    for link in KUKA_LIKE.links:
        write_stl(root / "pkgs" / "kuka_like" / "meshes" / f"{link}.stl", (0.08, 0.08, 0.08))
    uris = {link: f"package://kuka_like/meshes/{link}.stl" for link in KUKA_LIKE.links}
    write_urdf(root / "robot" / "kuka_like.urdf", KUKA_LIKE.with_(mesh_uris=uris))


def test_urdf_path_and_package_paths_are_relative_to_the_cell_file(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    _kuka_with_meshes(tmp_path / "job")
    cell = _write_cell(tmp_path / "job", "robot/kuka_like.urdf", "[pkgs]")
    monkeypatch.chdir(tmp_path)  # not the cell's folder
    monkeypatch.delenv("ROS_PACKAGE_PATH", raising=False)
    arm = load_cell(cell).build_arm()
    assert arm.joint_names[0] == "joint_a1"
    assert sum(len(v) for v in arm.loaded.meshes.values()) == 7


def test_cell_show_and_ik_with_a_urdf_cell(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    _kuka_with_meshes(tmp_path)
    cell = _write_cell(tmp_path, "robot/kuka_like.urdf", "[pkgs]")
    code = main(["cell", "show", str(cell), "--roll-step-deg", "90"])
    out = capsys.readouterr().out
    assert code in (0, 1), out
    assert "kuka_like" in out and "7 collision meshes" in out
    assert "signs [-1, 1, 1, -1, 1, -1]" in out
    assert "D-H     derived from the same axes" in out


def test_shipped_urdf_as_a_path_works_like_the_name(tmp_path: Path) -> None:
    cell = _write_cell(tmp_path, str(URDF_DIR / "abb_irb2600_20_165.urdf"))
    arm = load_cell(cell).build_arm()
    assert arm.dh == dh_table("abb_irb2600_20_165")
    q = np.array([0.1, 0.2, -0.3, 0.4, 0.5, 0.6])
    assert arm.ik(arm.fk(q)).ok


def test_thermal_resolves_the_model_against_the_cell_folder(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    folder = tmp_path / "cells"
    folder.mkdir()
    (folder / "arm.urdf").write_text((URDF_DIR / "abb_irb4600_60_205.urdf").read_text())
    cfg = load_cell(_write_cell(folder, "arm.urdf"))
    monkeypatch.chdir(tmp_path)
    assert _table_of(cfg) == dh_table("abb_irb4600_60_205")


def _problem(path: Path) -> tuple[str, object, str]:
    with pytest.raises(ConfigError) as info:
        load_cell(path)
    return info.value.problems[0]


def test_limits_position_narrows_and_refuses_a_widening(tmp_path: Path) -> None:
    narrow = "[[-1, 1], [-1, 1.5], [-2, 1], [-3, 3], [-2, 2], [-3, 3]]"
    arm = load_cell(_write_cell(tmp_path / "a", "abb_irb2600_20_165", position=narrow)).build_arm()
    assert arm.upper[1] == 1.5 and arm.urdf_upper[1] == pytest.approx(2.705)
    wide = "[[-1, 1], [-1, 3.0], [-2, 1], [-3, 3], [-2, 2], [-3, 3]]"
    field, _, msg = _problem(_write_cell(tmp_path / "b", "abb_irb2600_20_165", position=wide))
    assert field == "robot.limits.position"
    assert "joint_2" in msg and "widens" in msg
    field, _, _ = _problem(_write_cell(tmp_path / "c", "abb_irb2600_20_165", position="[[0, 1]]"))
    assert field.startswith("robot.limits.position")


def test_missing_mesh_in_a_cell_names_the_link_and_path(tmp_path: Path) -> None:
    _kuka_with_meshes(tmp_path)
    (tmp_path / "pkgs" / "kuka_like" / "meshes" / "arm_3.stl").unlink()
    field, _, msg = _problem(_write_cell(tmp_path, "robot/kuka_like.urdf", "[pkgs]"))
    assert field == "robot.model"
    assert "'arm_3'" in msg and "package://kuka_like/meshes/arm_3.stl" in msg


def test_missing_urdf_file_is_named(tmp_path: Path) -> None:
    field, _, msg = _problem(_write_cell(tmp_path, "robot/nothing.urdf"))
    assert field == "robot.model" and "no such file" in msg


def test_plan_a_urdf_cell_and_check_every_sample(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from planner.tour import load_tour

    _kuka_with_meshes(tmp_path)
    cell = _write_cell(tmp_path, "robot/kuka_like.urdf", "[pkgs]")
    code = main(["plan", str(cell), "-o", str(tmp_path / "tour.json"), "--quiet"])
    assert code == 0, capsys.readouterr().out
    tour = load_tour(tmp_path / "tour.json")
    assert tuple(tour.joint_names) == KUKA_LIKE.names
    arm = load_cell(cell).build_arm()
    traj = np.asarray(tour.trajectory, float)
    assert len(traj) > 10 and not any(arm.in_collision(q) for q in traj)
    assert np.all(traj >= arm.lower - 1e-9) and np.all(traj <= arm.upper + 1e-9)
