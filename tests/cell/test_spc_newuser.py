"""``holecell spc`` as a new user meets it: one run, a missing path, a file for a folder; and
one summary line for the characteristics without statistics."""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np
from qif_reports import NOMINALS, gdt_report

from cell.cli import main
from cell.review.qif import write_qif


def _runs(root: Path, n: int) -> Path:
    rng = np.random.default_rng(3)
    for i in range(n):
        d = root / f"run{i:03d}"
        d.mkdir(parents=True)
        write_qif(gdt_report(rng, 1.8e9 + 60.0 * i), d / "report.qif", NOMINALS)
    return root


def test_one_run_is_refused_in_one_line_and_nothing_written(tmp_path: Path, capsys) -> None:
    run = _runs(tmp_path / "runs", 1) / "run000"
    assert main(["spc", str(run)]) == 2
    out, err = capsys.readouterr()
    (line,) = err.strip().splitlines()
    assert out == ""
    assert line.startswith(f"holecell spc: error: {run}: statistics need a characteristic ")
    assert "evaluated in two runs or more; none of the" in line
    assert not (run / "spc.csv").exists() and not (run / "spc.html").exists()


def test_characteristics_without_statistics_are_one_summary_line(tmp_path: Path, capsys) -> None:
    runs = _runs(tmp_path / "runs", 3)
    assert main(["spc", str(runs)]) == 0
    lines = capsys.readouterr().out.strip().splitlines()
    assert "statistics need two" not in "\n".join(lines)
    head = lines[0]
    assert head.startswith("3 runs, ") and ": statistics for " in head
    assert head.endswith("not for 2 (evaluated in fewer than two runs: H2.diameter, H2.position)")
    assert all("Cpk" in s for s in lines[1:-1]) and lines[-1].startswith("wrote ")


def test_a_missing_path_or_a_file_is_named_as_such(tmp_path: Path, capsys) -> None:
    assert main(["spc", str(tmp_path / "nope")]) == 2
    assert f"{tmp_path / 'nope'}: no such file or folder" in capsys.readouterr().err
    f = tmp_path / "report.qif"
    f.write_text("x")
    assert main(["spc", str(f)]) == 2
    assert "a file, not a run directory (give the folder holding report.qif)" in (
        capsys.readouterr().err
    )


def test_a_cpk_from_two_runs_comes_with_its_interval_and_a_warning(tmp_path: Path, capsys):
    root = _runs(tmp_path / "runs", 2)
    assert main(["spc", str(root), "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "warning: 2 runs, fewer than the 25 a capability study needs" in out
    assert "AIAG SPC manual 2nd ed., ISO 22514-2" in out and "95 % interval" in out
    rows = list(csv.DictReader((tmp_path / "spc.csv").open()))
    with_cpk = [r for r in rows if r["cpk"]]
    assert with_cpk and all(float(r["cpk_ci95_low"]) < float(r["cpk"]) < float(r["cpk_ci95_high"])
                            and r["capability_note"] for r in with_cpk)  # fmt: skip
    assert "&#8224;" in (tmp_path / "spc.html").read_text()
