"""``holecell plan-batch``: a tour per cell, a summary CSV, failures listed, resume skips."""

from __future__ import annotations

import csv
from pathlib import Path

import yaml

from cell.cli import main
from cell.config import builtin_cell_path
from cell.config.datums import without_drawing
from planner import load_tour


def _variant(tmp_path: Path, name: str, shift_m: float) -> Path:
    data = yaml.safe_load(builtin_cell_path().read_text())
    data["name"] = name
    data["part"]["holes"] = data["part"]["holes"][:2]
    without_drawing(data, 5e-5)  # the subset may leave datum features out
    data["part"]["base"]["xyz"][1] += shift_m
    path = tmp_path / f"{name}.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


def _summary(out: Path) -> dict[str, dict[str, str]]:
    with (out / "summary.csv").open() as f:
        return {Path(r["cell_file"]).stem: r for r in csv.DictReader(f)}


def test_batch_plans_each_cell_lists_failures_and_resumes(tmp_path: Path, capsys) -> None:
    a = _variant(tmp_path, "variant-a", 0.0)
    broken = tmp_path / "broken.yaml"
    broken.write_text("name: x\nrobot: {model: no_such_robot}\n")
    out = tmp_path / "tours"
    args = ["plan-batch", str(broken), str(a), "-o", str(out), "--starts", "1"]
    assert main(args) == 1  # one cell failed, the batch went on
    rows = _summary(out)
    assert rows["variant-a"]["status"] == "complete" and rows["variant-a"]["planned"] == "now"
    assert rows["broken"]["status"] == "failed" and "broken.yaml" in rows["broken"]["error"]
    tour_a = load_tour(out / "variant-a.tour.json")
    assert tour_a.cell_name == "variant-a" and len(tour_a.stops) == 2
    assert float(rows["variant-a"]["cycle_time_s"]) == round(tour_a.cycle_time_s, 4)
    assert "failed  " in capsys.readouterr().out

    # resumed: the finished cell is skipped (no planning), the broken one listed again
    assert main(args) == 1
    rows = _summary(out)
    assert rows["variant-a"]["planned"] == "earlier" and rows["broken"]["status"] == "failed"
    assert "skipped (finished earlier)" in capsys.readouterr().err

    # after a fixture change (the cell file's text differs) the cell is planned again
    a.write_text(a.read_text().replace("name: variant-a", "name: variant-a2"))
    assert main(args[:1] + args[2:]) == 0
    assert _summary(out)["variant-a"]["planned"] == "now"
    assert load_tour(out / "variant-a.tour.json").cell_name == "variant-a2"
