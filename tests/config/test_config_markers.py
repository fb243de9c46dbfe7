"""Reference markers and scale bars in the cell file: the built-in layout, and refusals that
name the field."""

from __future__ import annotations

import pytest

from cell.camera import cell_stereo
from cell.config import builtin_cell_path, load_builtin_cell, parse_cell
from cell.errors import ConfigError
from cell.referencing.layout import markers_seen_per_hole

BASE = builtin_cell_path().read_text()
MARKERS = BASE[BASE.index("reference_markers:") :]
HEAD = BASE[: BASE.index("reference_markers:")]


def _cell(tail: str):
    return parse_cell(HEAD + tail, "cell.yaml", builtin_cell_path())


def test_every_hole_of_the_built_in_cell_sees_four_spread_markers() -> None:
    cell = load_builtin_cell()
    assert {m.on for m in cell.reference_markers} == {"part", "fixture"}  # YAML's `on` key
    seen = markers_seen_per_hole(cell, cell_stereo(cell))
    assert all(len(v) >= 4 for v in seen.values()), [k for k, v in seen.items() if len(v) < 4]
    assert len(cell.scale_bars) == 2


@pytest.mark.parametrize(
    ("tail", "field"),
    [
        (MARKERS.replace("id: P002,", "id: P001,", 1), "reference_markers[1].id: duplicate id"),
        (
            MARKERS.replace("from: T01", "from: T99"),
            "scale_bars[0].from: names no reference marker",
        ),
        (MARKERS.replace("length_m: 1.4", "length_m: 1400", 1), "scale_bars[0].length_m"),
        (MARKERS.replace("on: part", "on: robot", 1), "reference_markers[0].on"),
        (
            MARKERS.replace("diameter_m: 0.005", "diameter_m: 5", 1),
            "reference_markers[0].diameter_m",
        ),
        (  # the first marker carries code 1, which is the second one's place in the list
            MARKERS.replace("on: part}", "on: part, code: 1}", 1),
            "reference_markers[1].code: duplicate code",
        ),
    ],
)
def test_bad_markers_are_refused_naming_the_field(tail: str, field: str) -> None:
    with pytest.raises(ConfigError, match=field.replace("[", r"\[").replace("]", r"\]")):
        _cell(tail)
