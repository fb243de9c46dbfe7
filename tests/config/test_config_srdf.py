"""A MoveIt SRDF in the cell file (``robot.srdf``, cell/config/srdf.py): its disabled collision
pairs and named states."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml

from cell.config import builtin_cell_path, load_cell
from cell.errors import CellError, ConfigError

HOME = [0.0, -0.3, 0.3, 0.0, 1.2, 0.0]


def _srdf(states: str = "", disabled: str = "") -> str:
    return f"""<?xml version="1.0"?>
<robot name="abb_irb2600">
  <group name="manipulator"><chain base_link="base_link" tip_link="tool0"/></group>
  {states}
  <end_effector name="head" parent_link="tool0" group="manipulator"/>
  {disabled}
</robot>
"""


def _home_state(values: list[float], name: str = "home") -> str:
    joints = "".join(f'<joint name="joint_{i + 1}" value="{v}"/>' for i, v in enumerate(values))
    return f'<group_state name="{name}" group="manipulator">{joints}</group_state>'


def _cell(tmp_path: Path, srdf_text: str, home: object = "home") -> Path:
    data = yaml.safe_load(builtin_cell_path().read_text())
    data["robot"]["home"] = home
    data["robot"]["srdf"] = "arm.srdf"
    (tmp_path / "arm.srdf").write_text(srdf_text)
    path = tmp_path / "cell.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def _pairs(cfg, a: str, b: str) -> int:
    col = cfg.build_arm().collision
    bodies = [i.body for i in col.infos]
    return sum(
        1 for p in col.geom_model.collisionPairs if {bodies[p.first], bodies[p.second]} == {a, b}
    )


def test_named_home_and_disabled_pairs(tmp_path: Path) -> None:
    text = _srdf(
        _home_state(HOME) + _home_state([0, 0, 0, 0, 0.5, 0], "ready"),
        '<disable_collisions link1="link_1" link2="link_3" reason="Never"/>',
    )
    cfg = load_cell(_cell(tmp_path, text))
    assert np.allclose(cfg.home_q(), HOME)
    plain = load_cell(builtin_cell_path())
    assert _pairs(plain, "link_1", "link_3") > 0
    assert _pairs(cfg, "link_1", "link_3") == 0
    assert _pairs(cfg, "link_1", "link_4") == _pairs(plain, "link_1", "link_4")


@pytest.mark.parametrize(
    ("text", "home", "expect"),
    [
        (_srdf(_home_state(HOME)), "park", "no group_state 'park' (known: home)"),
        (_srdf(_home_state(HOME[:5])), "home", "no value for joints ['joint_6']"),
        ("<robot><group_state", "home", "not an SRDF (XML)"),
        (_srdf(_home_state(HOME), '<disable_collisions link1="link_1" link2="wrist"/>'), HOME,
         "links not in the URDF abb_irb2600_20_165.urdf (value: ['wrist'])"),
    ],
)  # fmt: skip
def test_srdf_mistakes_name_the_file(tmp_path: Path, text: str, home: object, expect: str) -> None:
    with pytest.raises(CellError) as err:
        load_cell(_cell(tmp_path, text, home)).build_arm()
    assert expect in str(err.value) and "arm.srdf" in str(err.value)


def test_a_state_name_without_srdf_is_refused(tmp_path: Path) -> None:
    data = yaml.safe_load(builtin_cell_path().read_text())
    data["robot"]["home"] = "home"
    path = tmp_path / "cell.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    with pytest.raises(ConfigError, match=r"needs robot\.srdf"):
        load_cell(path)
