"""``holecell thermal`` refuses bad inputs with one line naming the file, line and column."""

from __future__ import annotations

from pathlib import Path

import pytest

from cell.cli import main


def _model(tmp_path: Path) -> Path:
    obs, model = tmp_path / "obs.csv", tmp_path / "thermal.json"
    assert (
        main(["thermal", "simulate", "--cell", "motorcycle_frame", "-o", str(obs), "--hours", "1"])
        == 0
    )
    assert (
        main(["thermal", "identify", str(obs), "--cell", "motorcycle_frame", "-o", str(model)]) == 0
    )
    return model


def test_predict_refuses_joints_outside_the_limits(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    model = _model(tmp_path)
    header = "q1_rad,q2_rad,q3_rad,q4_rad,q5_rad,q6_rad," + ",".join(
        f"temp_j{i}_degC" for i in range(1, 7)
    )
    poses = tmp_path / "poses.csv"
    poses.write_text(header + "\n0,0,0,0,9.0,0," + ",".join(["25"] * 6) + "\n")
    capsys.readouterr()
    code = main(["thermal", "predict", str(model), str(poses), "--command"])
    err = capsys.readouterr().err
    assert code == 2
    assert err.startswith("holecell thermal: error: ")
    assert "line 2" in err and "q5_rad" in err and "outside" in err


def test_binary_csv_and_nan_duration_are_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    binary = tmp_path / "obs.csv"
    binary.write_bytes(b"time_s,\xff\xfe\n")
    code = main(
        [
            "thermal",
            "identify",
            str(binary),
            "--cell",
            "motorcycle_frame",
            "-o",
            str(tmp_path / "m.json"),
        ]
    )
    assert code == 2 and "UTF-8" in capsys.readouterr().err
    code = main(
        [
            "thermal",
            "simulate",
            "--cell",
            "motorcycle_frame",
            "-o",
            str(tmp_path / "o.csv"),
            "--hours",
            "nan",
        ]
    )
    assert code == 2 and "--hours" in capsys.readouterr().err
    assert not (tmp_path / "m.json").exists()
