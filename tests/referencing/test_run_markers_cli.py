"""``holecell run --markers``: a missing, foreign or malformed file is refused in one line
before anything is connected or written (another cell's or head's survey, and an old one: the
library's tests in test_survey.py)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from referencing_cells import small_cell_text

from cell.cli import main
from cell.config import load_cell
from planner import Options, plan_tour


@pytest.fixture(scope="module")
def files(tmp_path_factory) -> dict[str, Path]:
    root = tmp_path_factory.mktemp("runmarkers")
    cell = root / "small.yaml"
    cell.write_text(small_cell_text())
    tour = plan_tour(load_cell(cell), Options(seed=1)).save(root / "tour.json")
    return {"root": root, "cell": cell, "tour": tour}


def _run(files, markers: Path, tmp_path: Path, capsys, *extra: str) -> tuple[int, str]:
    out = tmp_path / "run"
    code = main(["run", str(files["tour"]), "--cell", str(files["cell"]), "--port",
                 "/dev/null-no-such-port", "--camera", "tcp://127.0.0.1:9", "--markers",
                 str(markers), "--out", str(out), *extra])  # fmt: skip
    err = capsys.readouterr().err.strip()
    assert not out.exists()
    return code, err


def test_a_malformed_markers_file_is_refused_in_one_line(files, tmp_path, capsys) -> None:
    bad = tmp_path / "markers.json"
    bad.write_text(json.dumps({"format": "holecell.markers", "version": 1, "markers": [{}]}))
    code, err = _run(files, bad, tmp_path, capsys)
    assert code == 2 and len(err.splitlines()) == 1 and "markers" in err, err


def test_a_missing_or_foreign_markers_file_is_refused(files, tmp_path, capsys) -> None:
    code, err = _run(files, tmp_path / "nope.json", tmp_path, capsys)
    assert code == 2 and "nope.json" in err and len(err.splitlines()) == 1, err
    wrong = tmp_path / "m.json"
    wrong.write_text(json.dumps({"format": "holecell.cellcal", "version": 1}))
    code, err = _run(files, wrong, tmp_path, capsys)
    assert code == 2 and "format" in err and len(err.splitlines()) == 1, err
