"""Cell file validation: every error names the file, the field path and the value."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml

from cell.config import builtin_cell_path, load_cell, parse_cell
from cell.errors import ConfigError
from robots import Arm

EXAMPLE = """
name: example
robot:
  model: abb_irb2600_20_165
  base: {xyz: [0, 0, 0], rpy: [0, 0, 0]}
  home: [0, 0, 0, 0, 0.5236, 0]
  limits: {velocity_scale: 1.0, acceleration_scale: 1.0, jerk_scale: 1.0}
tool:
  tool0_to_tcp: {xyz: [0, 0, 0.15], rpy: [0, 0, 0]}
  standoff_m: 0.25
  shapes:
    - {box: {size: [0.24, 0.12, 0.10]}, pose: {xyz: [0, 0, 0.08], rpy: [0, 0, 0]}}
part:
  base: {xyz: [1.1, 0, 0.55], rpy: [0, 0, 0]}
  holes:
    - {id: H01, position: [0.0, 0.1, 0.2], normal: [0, 0, 1], diameter: 0.0194, tolerance: 0.00005}
    - {id: H02, position: [0.0, -0.1, 0.2], normal: [0, 0, 1], diameter: 0.010}
  obstacles:
    - {cylinder: {radius: 0.02, length: 0.6}, pose: {xyz: [0, 0, 0.1], rpy: [0, 1.5708, 0]}}
    - {box: {size: [0.1, 0.1, 0.1]}, pose: {xyz: [0.3, 0, 0], rpy: [0, 0, 0]}}
    - {sphere: {radius: 0.05}, pose: {xyz: [0, 0.2, 0], rpy: [0, 0, 0]}}
environment:
  obstacles: []
reference_targets:
  - {id: R1, position: [0.9, -0.5, 0.3], normal: [0, 0, 1], diameter: 0.010}
"""


def _with(change) -> str:
    data = yaml.safe_load(EXAMPLE)
    change(data)
    return yaml.safe_dump(data)


def _problem(text: str) -> tuple[str, object, str]:
    with pytest.raises(ConfigError) as info:
        parse_cell(text, "cell.yaml")
    assert str(info.value).startswith("cell.yaml: ")
    return info.value.problems[0]


def test_example_from_the_issue_loads() -> None:
    cfg = parse_cell(EXAMPLE, "cell.yaml")
    assert [h.id for h in cfg.part.holes] == ["H01", "H02"]
    holes = cfg.holes_in_cell()
    assert np.allclose(holes[0].position_m, [1.1, 0.1, 0.75])
    arm = cfg.build_arm()
    assert len(arm.obstacles) == 3 and len(arm.tool_shapes) == 1
    assert np.allclose(
        arm.fk(cfg.home_q(), "tcp"), arm.fk(cfg.home_q(), "tool0") @ cfg.T_tool0_tcp()
    )


def test_builtin_cell_is_valid_and_large_enough() -> None:
    cfg = load_cell(None)
    assert cfg.source_path == builtin_cell_path().resolve()
    holes = cfg.part.holes
    assert len(holes) >= 40
    assert all(0.006 <= h.diameter <= 0.020 for h in holes)
    assert len(cfg.reference_targets) >= 2
    normals = np.array([h.normal for h in cfg.holes_in_cell()])
    assert len({tuple(np.round(n, 2)) for n in normals}) >= 6  # many directions


def test_unknown_key() -> None:
    field, value, msg = _problem(_with(lambda d: d["part"]["holes"][1].update(colour="red")))
    assert field == "part.holes[1].colour" and msg == "unknown key" and value == "red"


def test_wrong_type() -> None:
    field, value, _ = _problem(_with(lambda d: d["tool"].update(standoff_m="far")))
    assert field == "tool.standoff_m" and value == "far"


@pytest.mark.parametrize(("normal", "words"), [([0, 0, 2], "unit length"), ([0, 0, 0], "non-zero")])
def test_bad_normals(normal: list[float], words: str) -> None:
    field, value, msg = _problem(_with(lambda d: d["part"]["holes"][0].update(normal=normal)))
    assert field == "part.holes[0].normal" and value == normal and words in msg


def test_duplicate_hole_ids() -> None:
    field, value, msg = _problem(_with(lambda d: d["part"]["holes"][1].update(id="H01")))
    assert field == "part.holes[1].id" and value == "H01" and "duplicate" in msg


def test_home_outside_limits() -> None:
    field, value, msg = _problem(_with(lambda d: d["robot"].update(home=[0, 0, 0, 0, 3.0, 0])))
    assert field == "robot.home" and value == [0, 0, 0, 0, 3.0, 0] and "joint_5" in msg


def test_home_in_collision() -> None:
    # an environment ball around the home flange
    flange = Arm().fk([0, 0, 0, 0, 0.5236, 0], "flange")[:3, 3].tolist()

    def change(d: dict) -> None:
        d["environment"]["obstacles"] = [
            {"sphere": {"radius": 0.1}, "pose": {"xyz": flange, "rpy": [0, 0, 0]}}
        ]

    field, _, msg = _problem(_with(change))
    assert field == "robot.home" and "in collision" in msg


def test_zero_size_shape_and_two_kinds() -> None:
    field, _, _ = _problem(_with(lambda d: d["part"]["obstacles"][2]["sphere"].update(radius=0)))
    assert field == "part.obstacles[2].sphere.radius"
    field, _, msg = _problem(
        _with(lambda d: d["part"]["obstacles"][1].update(sphere={"radius": 0.1}))
    )
    assert field == "part.obstacles[1]" and "exactly one" in msg


def test_unknown_model() -> None:
    field, value, msg = _problem(_with(lambda d: d["robot"].update(model="kuka_kr16")))
    assert field == "robot.model" and value == "kuka_kr16" and "unknown robot model" in msg


def test_missing_file_and_bad_yaml(tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match="no such file"):
        load_cell(tmp_path / "absent.yaml")
    bad = tmp_path / "bad.yaml"
    bad.write_text("name: [unclosed\n")
    with pytest.raises(ConfigError, match=r"bad.yaml: line 2, column 1: not valid YAML: expected"):
        load_cell(bad)


def test_nan_and_inf_are_refused() -> None:
    field, _, _ = _problem(_with(lambda d: d["part"]["base"].update(xyz=[float("nan"), 0, 0])))
    assert field == "part.base.xyz[0]"
    field, _, _ = _problem(_with(lambda d: d["tool"].update(standoff_m=float("inf"))))
    assert field == "tool.standoff_m"


def test_pose_needs_exactly_one_rotation() -> None:
    field, _, msg = _problem(_with(lambda d: d["part"]["base"].pop("rpy")))
    assert field == "part.base" and "exactly one of rpy or quat_xyzw" in msg
    both = {"xyz": [0, 0, 0], "rpy": [0, 0, 0], "quat_xyzw": [0, 0, 0, 1]}
    field, _, _ = _problem(_with(lambda d: d["part"].update(base=both)))
    assert field == "part.base"
    quat = {"xyz": [1.1, 0, 0.55], "quat_xyzw": [0, 0, 0, 1]}
    assert (
        parse_cell(_with(lambda d: d["part"].update(base=quat)), "cell.yaml").part.base.rpy is None
    )


def test_directory_and_binary_files_are_refused(tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match="is a directory"):
        load_cell(tmp_path)
    binary = tmp_path / "cell.yaml"
    binary.write_bytes(b"name: \xff\xfe\x00bad")
    with pytest.raises(ConfigError, match="UTF-8"):
        load_cell(binary)


def test_missing_calibration_file_and_package_folder_are_named(tmp_path) -> None:
    from cell.config import DATA_DIR, load_cell
    from cell.errors import ConfigError

    text = (DATA_DIR / "motorcycle_frame.yaml").read_text()
    text = text.replace("tool:\n", "tool:\n  calibration: head/stereo.json\n", 1)
    text = text.replace("robot:\n", "robot:\n  package_paths: [ros_ws/src]\n", 1)
    path = tmp_path / "cell.yaml"
    path.write_text(text)
    with pytest.raises(ConfigError) as err:
        load_cell(path)
    msg = str(err.value)
    assert "tool.calibration" in msg and "head/stereo.json" in msg and "no such file" in msg
    assert "robot.package_paths[0]" in msg and "no such folder" in msg
    (tmp_path / "head").mkdir()
    (tmp_path / "head" / "stereo.json").write_text("{}")
    (tmp_path / "ros_ws" / "src").mkdir(parents=True)
    assert load_cell(path).calibration_path() == tmp_path / "head" / "stereo.json"
