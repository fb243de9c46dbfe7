"""Command-line mistakes are refused at once with a clear message, before anything is planned,
connected or written; the reference tour visits the designed views."""

from __future__ import annotations

import logging
from pathlib import Path

import numpy as np
import pytest
from cell_fixtures import SmallCell

from cell.cli import main
from cell.run.reference import design_reference_plan, plan_reference_tour, target_of
from planner import Options


def _run(sc: SmallCell, out: Path) -> list[str]:
    return ["run", str(sc.tour_path), "--cell", str(sc.path), "--out", str(out),
            "--port", "/nonexistent/port", "--camera", "tcp://127.0.0.1:1"]  # fmt: skip


def test_run_out_is_a_file(small_cell: SmallCell, tmp_path: Path, capsys) -> None:
    out = tmp_path / "a_file"
    out.write_text("keep me")
    assert main(_run(small_cell, out)) == 2
    err = capsys.readouterr().err
    assert "a_file" in err and "not a directory" in err and "/nonexistent/port" not in err
    assert out.read_text() == "keep me"


def test_run_out_holds_a_run(small_cell: SmallCell, tmp_path: Path, capsys) -> None:
    (tmp_path / "results.sqlite").write_bytes(b"stored run")
    assert main(_run(small_cell, tmp_path)) == 2
    err = capsys.readouterr().err
    assert "stored here already" in err and f"--resume {tmp_path}" in err


def test_demo_out_holds_a_run_refused_before_planning(tmp_path: Path, capsys) -> None:
    (tmp_path / "results.sqlite").write_bytes(b"stored run")
    assert main(["demo", "--out", str(tmp_path), "--quiet", "--no-record"]) == 2
    err = capsys.readouterr().err
    assert "stored here already" in err and "another --out" in err and "--resume" not in err
    assert (tmp_path / "results.sqlite").read_bytes() == b"stored run"


@pytest.mark.parametrize("argv", [["--speed", "0"], ["--speed", "-1"], ["--speed", "inf"],
                                  ["--estop-at", "-3"], ["--drop", "1.5"]])  # fmt: skip
def test_sim_refuses_bad_numbers(argv: list[str], capsys) -> None:
    with pytest.raises(SystemExit) as exc:
        main(["sim", *argv, "--duration-s", "0.1"])
    assert exc.value.code == 2 and argv[0] in capsys.readouterr().err


def test_sim_refuses_an_unknown_missing_hole(small_cell: SmallCell, capsys) -> None:
    code = main(["sim", str(small_cell.path), "--missing", "NOPE", "--duration-s", "0.1"])
    err = capsys.readouterr().err
    assert code == 2 and "NOPE" in err and "--missing" in err and "Traceback" not in err


def test_reference_tour_visits_the_designed_views(small_cell: SmallCell, caplog) -> None:
    """The runner's reference tour is the designed plan: every designed view, at exactly its
    joint vector, nothing left out, no warning."""
    design = design_reference_plan(small_cell.cell, np.array([s.q for s in small_cell.tour.stops]))
    with caplog.at_level(logging.INFO):
        tour = plan_reference_tour(small_cell.cell, Options(seed=1), tour=small_cell.tour)
    assert not tour.left_out and len(tour.stops) == len(design.views)
    for s in tour.stops:
        view = design.views[int(s.hole_id.split("#")[1])]
        assert target_of(s.hole_id) == view.target_id
        assert np.allclose(s.q, view.q_rad, atol=1e-12)
    assert not [r for r in caplog.records if r.levelno >= logging.WARNING]


def test_run_default_reference_rounds_can_identify() -> None:
    from cell.cli import build_parser
    from cell.run.runner import RunOptions

    args = build_parser().parse_args(["run", "t.json", "--port", "p", "--camera", "c"])
    assert args.reference_rounds == RunOptions().reference_rounds >= 2


@pytest.mark.parametrize(
    ("args", "word"),
    [
        (["--part-temperature", "293.15"], "kelvin"),
        (["--part-temperature", "warm"], "not a number"),
        (["--u-part-temperature", "-1"], "not positive"),
        (["--decision", "lenient"], "invalid choice"),
    ],
)
def test_run_refuses_bad_part_temperature_and_rule(
    small_cell: SmallCell, tmp_path: Path, capsys, args: list[str], word: str
) -> None:
    """Refused by the argument parser (exit 2) with the option named; nothing is written."""
    with pytest.raises(SystemExit) as exc:
        main([*_run(small_cell, tmp_path / "r"), *args])
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert args[0] in err and word in err
    assert not (tmp_path / "r").exists()
