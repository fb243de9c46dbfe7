"""``holecell plan``: writes tour.json, prints a summary, exit codes, clear errors."""

from __future__ import annotations

from pathlib import Path

import yaml

from cell.cli import main
from cell.config import builtin_cell_path
from cell.config.datums import without_drawing
from planner import load_tour


def _cell_file(tmp_path: Path, extra: list[dict]) -> Path:
    data = yaml.safe_load(builtin_cell_path().read_text())
    data["name"] = "cli-test-cell"
    data["part"]["holes"] = data["part"]["holes"][:3] + extra
    without_drawing(data, 5e-5)  # the subset may leave datum features out
    path = tmp_path / "cell.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


def test_plan_writes_the_tour_and_a_summary(tmp_path: Path, capsys) -> None:
    cell = _cell_file(tmp_path, [])
    out = tmp_path / "tour.json"
    assert main(["plan", str(cell), "-o", str(out), "--seed", "3", "--quiet", "--starts", "1"]) == 0
    tour = load_tour(out)
    assert tour.cell_name == "cli-test-cell" and len(tour.stops) == 3
    assert tour.settings["seed"] == 3
    text = capsys.readouterr().out
    assert "3 in the tour, 0 left out" in text and "cycle time" in text and "planning time" in text


def test_left_out_holes_exit_1_and_strict_exits_2(tmp_path: Path, capsys) -> None:
    far = {"id": "FAR", "position": [4.0, 0.0, 0.0], "normal": [0, 0, 1], "diameter": 0.01}
    cell = _cell_file(tmp_path, [far])
    out = tmp_path / "tour.json"
    assert main(["plan", str(cell), "-o", str(out), "--quiet", "--starts", "1"]) == 1
    assert "FAR: out of reach" in capsys.readouterr().out
    out.unlink()
    assert main(["plan", str(cell), "-o", str(out), "--strict", "--quiet", "--starts", "1"]) == 2
    err = capsys.readouterr().err
    assert "FAR: out of reach" in err and "Traceback" not in err
    assert not out.exists()


def test_bad_arguments_are_one_line_errors(tmp_path: Path, capsys) -> None:
    assert main(["plan", str(tmp_path / "missing.yaml"), "-o", str(tmp_path / "t.json")]) == 2
    assert "missing.yaml" in capsys.readouterr().err
    assert main(["plan", "-o", str(tmp_path / "no" / "t.json")]) == 2
    assert "does not exist" in capsys.readouterr().err
    assert main(["plan", "--roll-step-deg", "0", "-o", str(tmp_path / "t.json")]) == 2
    assert "roll_step_deg" in capsys.readouterr().err
