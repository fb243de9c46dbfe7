"""A new user's command-line mistakes: one line on stderr, exit 2, nothing written, no
traceback (the usage errors of argparse too)."""

from __future__ import annotations

from pathlib import Path

import pytest

from cell.cli import main


def _one_line(capsys) -> str:
    out = capsys.readouterr()
    lines = out.err.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in out.err, out.err
    return lines[0]


@pytest.mark.parametrize(
    ("argv", "words"),
    [
        (["plan", "--seed", "x"], "holecell plan: error: argument --seed: invalid int value: 'x'"),
        (["truth", "draw", "-o", "t.yaml"], "the following arguments are required: --seed"),
        (["nosuch"], "invalid choice: 'nosuch'"),
    ],
)
def test_usage_errors_are_one_line_pointing_at_help(capsys, argv, words) -> None:
    with pytest.raises(SystemExit) as exc:
        main(argv)
    assert exc.value.code == 2
    line = _one_line(capsys)
    assert words in line and line.endswith("--help)")


def test_an_output_that_is_a_folder_or_in_none_is_refused_before_any_work(
    tmp_path: Path, capsys
) -> None:
    (tmp_path / "d").mkdir()
    runs = [
        ["thermal", "simulate", "--cell", "motorcycle_frame", "-o", str(tmp_path / "d")],
        ["truth", "draw", "--seed", "1", "-o", str(tmp_path / "no" / "t.yaml")],
        ["calibrate", "hand-eye", "--images", str(tmp_path), "--poses", "p.csv",
         "--intrinsics", "c.yaml", "--cols", "8", "--rows", "6", "--pitch", "0.012",
         "-o", str(tmp_path / "d")],
    ]  # fmt: skip
    for argv in runs:
        with pytest.raises(SystemExit) as exc:
            main(argv)
        assert exc.value.code == 2
        line = _one_line(capsys)
        assert "argument -o/--output: " in line
        assert "is a directory; give a file name" in line or "does not exist" in line
    assert sorted(p.name for p in tmp_path.rglob("*")) == ["d"]


@pytest.mark.parametrize(
    ("text", "words"),
    [
        ("", "not an OpenCV FileStorage file (empty or unreadable)"),
        ("just words\n", "not an OpenCV FileStorage file: Only collections as YAML streams"),
        ("%YAML:1.0\n---\n- 1\n- 2\n", "not a mapping of named nodes"),
        ("%YAML:1.0\n---\ncamera_matrix: 3\n", "camera_matrix: not an OpenCV matrix"),
        (None, "is a directory, not an intrinsics file"),
    ],
)
def test_a_bad_intrinsics_file_is_one_line(tmp_path: Path, capsys, text, words) -> None:
    from cell.calibration.errors import CalibrationDataError
    from cell.calibration.inputs import read_intrinsics

    p = tmp_path / "camera.yaml"
    if text is None:
        p.mkdir()
    else:
        p.write_text(text)
    with pytest.raises(CalibrationDataError) as exc:
        read_intrinsics(p, (640, 512))
    assert str(exc.value) == f"{p}: {words}" or str(exc.value).startswith(f"{p}: {words}")


def test_folders_given_for_files_and_missing_run_folders_are_named(tmp_path: Path, capsys):
    (tmp_path / "d").mkdir()
    d, missing = str(tmp_path / "d"), str(tmp_path / "nope")
    assert main(["sim", "--truth", d, "--duration-s", "0.1"]) == 2
    assert f"{d}: (file): is a directory, not a truth file" in _one_line(capsys)
    from measure.synth.heads import toed_in_stereo

    toed_in_stereo().save(tmp_path / "stereo.json")
    assert main(["measure", d, d, "--stereo", str(tmp_path / "stereo.json")]) == 2
    assert f"left image: {d}: is a directory, not an image" in _one_line(capsys)
    assert main(["report", missing]) == 2
    assert _one_line(capsys).endswith(f"{missing}: no such run directory")


def test_a_negative_seed_is_refused_by_the_planner_options(capsys) -> None:
    import numpy as np

    from planner import Options
    from planner.errors import OptionsError

    assert main(["plan", "--seed", "-1", "--quiet"]) == 2
    assert "planner option seed=-1: must be an integer in [0, " in _one_line(capsys)
    assert Options(seed=np.int64(3)).seed == 3
    with pytest.raises(OptionsError):
        Options(seed=2**40)


def test_calibrate_stereo_names_an_unmatched_glob(tmp_path, capsys):
    import cv2
    import numpy as np

    img = tmp_path / "l.png"
    cv2.imwrite(str(img), np.zeros((8, 8), np.uint8))
    board = ["--cols", "8", "--rows", "6"]
    nomatch = str(tmp_path / "none*.png")
    assert main(["calibrate", "stereo", "--left", nomatch, "--right", str(img), *board,
                 "--pitch", "0.012"]) == 2  # fmt: skip
    assert _one_line(capsys).endswith(f"--left {nomatch}: no image matches")


def test_a_missing_key_is_named_without_the_mapping_around_it(tmp_path: Path, capsys) -> None:
    p = tmp_path / "cell.yaml"
    p.write_text("x: 1\n")
    assert main(["cell", "show", str(p)]) == 2
    err = capsys.readouterr().err
    assert f"{p}: robot: a required key is missing\n" in err and "{'x': 1}" not in err
    t = tmp_path / "truth.yaml"
    t.write_text("tool: {tcp_error: {rpy: [0, 0, 0]}}\n")
    assert main(["sim", "--truth", str(t)]) == 2
    assert _one_line(capsys).endswith(f"{t}: tool.tcp_error.xyz: a required key is missing")


def test_thermal_simulate_and_measure_name_the_bad_number(tmp_path: Path, capsys) -> None:
    out = str(tmp_path / "o.csv")
    args = ["thermal", "simulate", "--cell", "motorcycle_frame", "-o", out, "--hours", "-1"]
    assert main(args) == 2
    line = _one_line(capsys)
    assert line.startswith("holecell thermal: error: --hours -1, --every-s ")
    with pytest.raises(SystemExit):
        main(["measure", "a.png", "b.png", "--stereo", "s.json", "--diameter", "12"])
    assert "--diameter: 12 m: metres expected, this looks like millimetres" in _one_line(capsys)


def test_help_names_every_report_file_the_exit_codes_and_the_readme_the_current_forms(capsys):
    from cell import cli

    with pytest.raises(SystemExit):
        cli.main(["--help"])
    out = capsys.readouterr().out
    assert "report.html and report.qif" in " ".join(out.split())  # argparse wraps the line
    assert "1    written, with something left out" in out and "2    a user mistake" in out
    readme = (Path(__file__).resolve().parents[2] / "README.md").read_text()
    commands = readme[readme.index("## The command line") : readme.index("## The cell file")]
    assert "holecell calibrate --left" not in commands
