"""``holecell calibrate example DIR``: a synthetic set that ``calibrate hand-eye`` calibrates
from with the command it prints, to the truth it writes."""

from __future__ import annotations

import json
import shlex
from pathlib import Path

import numpy as np

from cell.calibration.estimate import pose_error
from cell.calibration.file import load_calibration
from cell.cli import main


def _printed_command(out: str) -> list[str]:
    lines = out.strip().splitlines()
    assert lines[-2] == "calibrate with:"
    words = shlex.split(lines[-1])
    assert words[:3] == ["holecell", "calibrate", "hand-eye"]
    return words[1:]


def test_the_example_calibrates_with_the_printed_command(tmp_path: Path, capsys) -> None:
    d = tmp_path / "example"
    assert main(["calibrate", "example", str(d), "--views", "6", "--seed", "2"]) == 0
    cmd = _printed_command(capsys.readouterr().out)
    names = sorted(p.name for p in d.iterdir())
    assert names[:2] == ["L00.png", "L01.png"] and "stereo.json" in names
    assert "--cell" in cmd and (d / "poses.csv").read_text().startswith(
        "left_image,right_image,q1_rad"
    )
    assert main(cmd) == 0, capsys.readouterr().err
    cal = load_calibration(d / "cellcal.json")
    truth = json.loads((d / "truth.json").read_text())
    dp, da = pose_error(cal.T_tool0_camera.T, np.array(truth["T_tool0_camera"]))
    # within 5 of the calibration's own standard deviations (of the norm over 3 axes)
    he = cal.T_tool0_camera
    assert cal.counts["views"] == 6
    assert dp < 5 * np.linalg.norm(he.sigma_xyz_m) and da < 5 * np.linalg.norm(he.sigma_rot_rad)


def test_mono_flange_example_and_no_overwrite(tmp_path: Path, capsys) -> None:
    d = tmp_path / "mono"
    assert main(["calibrate", "example", str(d), "--views", "4", "--mono", "--flange"]) == 0
    cmd = _printed_command(capsys.readouterr().out)
    assert "--intrinsics" in cmd and "--cell" not in cmd
    assert (d / "poses.csv").read_text().startswith("image,x_m,y_m,z_m,qx,qy,qz,qw")
    before = sorted(p.name for p in d.iterdir())
    assert main(["calibrate", "example", str(d)]) == 2
    (line,) = capsys.readouterr().err.strip().splitlines()
    assert line.endswith(f"{d}: exists and is not an empty folder: nothing written")
    assert sorted(p.name for p in d.iterdir()) == before
