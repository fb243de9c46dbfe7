"""Drawing figures typed in millimetres into a cell file (in metres): refused naming the field,
one line each, with the unit hint; the built-in frame's figures pass."""

from __future__ import annotations

import pytest
import yaml

from cell.cli import main
from cell.config import builtin_cell_path, parse_cell
from cell.config.datums import without_drawing
from cell.errors import ConfigError


def _data() -> dict:
    return yaml.safe_load(builtin_cell_path().read_text())


def _eml1(d: dict) -> dict:
    return next(h for h in d["part"]["holes"] if h["id"] == "EML1")


@pytest.mark.parametrize(
    ("edit", "field"),
    [
        (lambda h: h["tolerances"]["position"].update(zone_diameter_m=0.5),
         "part.holes[6].tolerances.position.zone_diameter_m"),
        (lambda h: h["tolerances"]["size"].update(upper_m=0.036),
         "part.holes[6].tolerances.size.upper_m"),
        (lambda h: h["tolerances"]["size"].update(lower_m=-0.01, upper_m=0.01),
         "part.holes[6].tolerances.size.lower_m"),
        (lambda h: h.update(diameter=12.0), "part.holes[6].diameter"),
    ],
)  # fmt: skip
def test_millimetres_in_a_drawing_figure_are_refused(edit, field: str) -> None:
    data = _data()
    edit(_eml1(data))
    with pytest.raises(ConfigError) as exc:
        parse_cell(yaml.safe_dump(data), "frame.yaml")
    mine = [p for p in exc.value.problems if p[0] == field]
    assert len(mine) == 1, exc.value.problems
    assert "lengths are in metres, this looks like millimetres" in mine[0][2]


def test_the_old_single_tolerance_in_millimetres_is_refused() -> None:
    data = without_drawing(_data(), tolerance_m=0.05)
    with pytest.raises(ConfigError) as exc:
        parse_cell(yaml.safe_dump(data), "frame.yaml")
    fields = {p[0] for p in exc.value.problems}
    assert "part.holes[0].tolerance" in fields and len(fields) == len(data["part"]["holes"])


def test_realistic_loose_figures_pass() -> None:
    data = _data()
    h = _eml1(data)
    h["tolerances"]["position"].update(zone_diameter_m=0.004)  # a 4 mm zone: loose, real
    h["tolerances"]["size"].update(upper_m=0.001, lower_m=-0.001)  # +-1 mm (ISO 2768 coarse)
    parse_cell(yaml.safe_dump(data), "frame.yaml")


def test_cell_show_refuses_a_millimetre_zone_in_one_line(tmp_path, capsys) -> None:
    data = _data()
    _eml1(data)["tolerances"]["position"].update(zone_diameter_m=0.3)
    p = tmp_path / "cell.yaml"
    p.write_text(yaml.safe_dump(data))
    assert main(["cell", "show", str(p)]) == 2
    (line,) = capsys.readouterr().err.strip().splitlines()
    assert str(p) in line and "zone_diameter_m" in line and "millimetres" in line


def test_a_malformed_cell_file_is_one_line_with_the_line_number(tmp_path, capsys) -> None:
    p = tmp_path / "cell.yaml"
    p.write_text("robot:\n  home: [0, 0\n")
    assert main(["cell", "show", str(p)]) == 2
    (line,) = capsys.readouterr().err.strip().splitlines()
    assert f"{p}: line 3, column 1: not valid YAML" in line and "from line 2" in line
