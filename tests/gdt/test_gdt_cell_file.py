"""Datums and tolerances in the cell file: the built-in frame's drawing, and the refusals that
name the field."""

from __future__ import annotations

import pytest
import yaml

from cell.config import builtin_cell_path, load_builtin_cell, parse_cell
from cell.config.datums import without_drawing
from cell.errors import ConfigError


def _data() -> dict:
    return yaml.safe_load(builtin_cell_path().read_text())


def _problems(data: dict) -> list[tuple[str, object, str]]:
    with pytest.raises(ConfigError) as exc:
        parse_cell(yaml.safe_dump(data), "frame.yaml")
    return exc.value.problems


def _hole(data: dict, hole_id: str) -> tuple[int, dict]:
    return next((i, h) for i, h in enumerate(data["part"]["holes"]) if h["id"] == hole_id)


def test_builtin_frame_carries_its_drawing() -> None:
    cell = load_builtin_cell()
    d = {x.label: x for x in cell.part.datums}
    assert d["A"].kind == "plane" and d["B"].hole == "PVL" and d["C"].hole == "HT1"
    zones = [h.tolerances.position.zone_diameter_m for h in cell.part.holes
             if h.tolerances.position is not None]  # fmt: skip
    assert len(zones) == 39 and min(zones) == pytest.approx(2e-4) and max(zones) == 5e-4
    for h in cell.part.holes:
        s = h.tolerances.size
        assert s.lower_m == 0.0 and 18e-6 <= s.upper_m <= 130e-6  # ISO 286 H8..H11
        assert h.tolerance is None


@pytest.mark.parametrize(
    ("edit", "field", "words"),
    [
        (lambda d: d["part"]["datums"][1].update(hole="NOPE"), "part.datums[1].hole",
         "names no hole"),
        (lambda d: d["part"]["datums"][0]["plane"]["holes"].append("XX"),
         "part.datums[0].plane.holes[6]", "names no hole"),
        (lambda d: _hole(d, "EML1")[1]["tolerances"]["position"].update(datums=[]),
         "part.holes[6].tolerances.position.datums", "needs datums"),
        (lambda d: _hole(d, "EML1")[1]["tolerances"]["position"].update(zone_diameter_m=-1e-4),
         "part.holes[6].tolerances.position.zone_diameter_m", "negative"),
        (lambda d: _hole(d, "EML1")[1]["tolerances"]["size"].update(upper_m=-1e-5),
         "part.holes[6].tolerances.size", "wrong order"),
        (lambda d: _hole(d, "EML1")[1]["tolerances"]["position"].update(datums=["A", "D"]),
         "part.holes[6].tolerances.position.datums[1]", "no such datum"),
        (lambda d: _hole(d, "EML1")[1]["tolerances"]["position"].update(datums=["A", "B"]),
         "part.holes[6].tolerances.position.datums", "no complete frame"),
        (lambda d: _hole(d, "EML1")[1].update(tolerance=5e-5), "part.holes[6].tolerance",
         "not both"),
        (lambda d: _hole(d, "EML1")[1]["tolerances"].pop("size"),
         "part.holes[6].tolerances.position.material_condition", "size limits"),
        (lambda d: d["part"]["datums"].append({"label": "A", "hole": "PUL"}),
         "part.datums[3].label", "duplicate"),
    ],
)  # fmt: skip
def test_bad_drawings_are_refused_with_the_field_named(edit, field: str, words: str) -> None:
    data = _data()
    edit(data)
    problems = _problems(data)
    assert any(f == field and words in msg for f, _, msg in problems), problems


def test_refusal_is_one_line_per_problem_naming_file_and_field() -> None:
    data = _data()
    _hole(data, "EML1")[1]["tolerances"]["size"].update(upper_m=-1e-5)
    with pytest.raises(ConfigError) as exc:
        parse_cell(yaml.safe_dump(data), "frame.yaml")
    assert str(exc.value).startswith("frame.yaml: part.holes[6].tolerances.size: limits in the")
    assert "\n" not in str(exc.value)


def test_old_single_tolerance_keeps_working_and_subsets_drop_the_drawing() -> None:
    data = _data()
    data["part"]["holes"] = data["part"]["holes"][:2]
    with pytest.raises(ConfigError):  # the datum features are gone with the other holes
        parse_cell(yaml.safe_dump(data), "frame.yaml")
    cell = parse_cell(yaml.safe_dump(without_drawing(data, 5e-5)), "frame.yaml")
    assert [h.tolerance for h in cell.part.holes] == [5e-5, 5e-5]
    assert cell.part.datums == [] and all(h.tolerances is None for h in cell.part.holes)


def test_alignment_choices_are_validated() -> None:
    data = _data()
    data["part"]["alignment"] = {"best_fit": {"holes": ["PVL", "XX"]}}
    problems = _problems(data)
    assert ("part.alignment.best_fit.holes[1]", "XX", "no such hole") in problems
    data["part"]["alignment"] = {"datums": ["A", "B", "C"], "best_fit": {}}
    assert any("exactly one" in m for _, _, m in _problems(data))
