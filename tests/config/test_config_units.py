"""Lengths typed in millimetres where the cell file wants metres are refused with the hint,
naming the field: hole positions, poses, the tool's offset and stand-off (issue 26, finding 4:
they were accepted, and every hole came out unreachable)."""

from __future__ import annotations

import re

import pytest

from cell.config import builtin_cell_path, load_builtin_cell, parse_cell
from cell.errors import ConfigError

TEXT = builtin_cell_path().read_text()


@pytest.mark.parametrize(
    ("old", "new", "field"),
    [
        ("    position: [0.4192, 0.1071, 0.401]", "    position: [419.2, 107.1, 401]",
         "part.holes[0].position"),
        ("    xyz: [1.08, 0, 0.64]", "    xyz: [1080, 0, 640]", "part.base.xyz"),
        ("  standoff_m: 0.25", "  standoff_m: 250", "tool.standoff_m"),
        ("    xyz: [0, 0, 0.12]", "    xyz: [0, 0, 120]", "tool.tool0_to_tcp.xyz"),
    ],
)  # fmt: skip
def test_millimetres_are_refused_naming_the_field(old: str, new: str, field: str) -> None:
    assert old in TEXT
    pattern = re.escape(field) + ": .*lengths are in metres, this looks like millimetres"
    with pytest.raises(ConfigError, match=pattern):
        parse_cell(TEXT.replace(old, new, 1), "cell.yaml", builtin_cell_path())


def test_the_built_in_cell_passes() -> None:
    assert load_builtin_cell().tool.standoff_m == 0.25
