"""A new user's truth-file mistakes: one short line each, naming the file, the field or line."""

from __future__ import annotations

from pathlib import Path

import pytest

from cell.cli import main
from cell.errors import TruthFileError
from cell.sim.truth_file import read_truth_spec

SEVEN_ROWS = "robot:\n  dh_errors:\n" + "    - {a_m: 0.001}\n" * 6 + "    - {a_m: 0.001, foo: 1}\n"


def _lines(path: Path) -> list[str]:
    with pytest.raises(TruthFileError) as exc:
        read_truth_spec(path)
    return str(exc.value).splitlines()


def test_seven_dh_rows_give_the_count_and_the_unknown_key(tmp_path: Path) -> None:
    p = tmp_path / "truth.yaml"
    p.write_text(SEVEN_ROWS)
    lines = _lines(p)
    assert len(lines) == 2, lines
    assert lines[0] == f"{p}: robot.dh_errors: 7 rows: one per joint, 6 rows expected"
    assert lines[1] == f"{p}: robot.dh_errors[6].foo: unknown key (value: 1)"


def test_a_long_value_is_shortened(tmp_path: Path) -> None:
    p = tmp_path / "truth.yaml"
    p.write_text("robot: {base_error: [" + ", ".join(["0.001"] * 40) + "]}\n")
    (line,) = _lines(p)
    assert line.startswith(f"{p}: robot.base_error: ") and line.endswith("...)")
    assert len(line) < len(str(p)) + 160


def test_malformed_yaml_is_one_line_with_the_line_number(tmp_path: Path, capsys) -> None:
    p = tmp_path / "truth.yaml"
    p.write_text("seed: 3\nrobot:\n  dh_errors: [\n  tool: 1\n")
    (line,) = _lines(p)
    assert line.startswith(f"{p}: line 5, column 1: not valid YAML: expected ',' or ']'")
    assert "from line 3" in line and "(value" not in line
    assert main(["sim", "--truth", str(p), "--duration-s", "0.1"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "line 5" in err[0]
