"""``holecell cell show``: the summary of a cell, and clear errors instead of tracebacks."""

from __future__ import annotations

from pathlib import Path

import pytest

from cell.cli import main


def test_show_builtin_cell(capsys: pytest.CaptureFixture[str]) -> None:
    code = main(["cell", "show"])
    out = capsys.readouterr().out
    assert code == 0, out
    assert "abb_irb2600_20_165" in out
    assert "PVL" in out and "R1*" in out
    assert "reachable" in out


def test_show_reports_an_unreachable_hole(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    cell = tmp_path / "far.yaml"
    cell.write_text(
        """
name: far
robot: {model: abb_irb2600_20_165, home: [0, 0, 0, 0, 0.5, 0]}
tool: {tool0_to_tcp: {xyz: [0, 0, 0.15], rpy: [0, 0, 0]}, standoff_m: 0.25}
part:
  base: {xyz: [3.0, 0, 0.5], rpy: [0, 0, 0]}
  holes: [{id: FAR, position: [0, 0, 0], normal: [0, 0, 1], diameter: 0.01}]
"""
    )
    code = main(["cell", "show", str(cell), "--roll-step-deg", "90"])
    out = capsys.readouterr().out
    assert code == 1
    assert "UNREACHABLE: out of reach" in out
    assert "1 hole," in out and "0 obstacles" in out and "0 reference targets" in out


def test_bad_cell_file_gives_a_message_not_a_traceback(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    cell = tmp_path / "bad.yaml"
    cell.write_text("name: x\nrobot: {home: [0, 0, 0]}\n")
    code = main(["cell", "show", str(cell)])
    err = capsys.readouterr().err
    assert code == 2
    assert "bad.yaml: robot.home" in err
    assert "Traceback" not in err


def test_output_into_a_closed_pipe_is_no_traceback() -> None:
    import shutil
    import subprocess
    import sys
    from pathlib import Path

    exe = shutil.which("holecell") or str(Path(sys.executable).with_name("holecell"))
    proc = subprocess.run(
        f"'{exe}' cell show | head -c 1 >/dev/null; exit ${{PIPESTATUS[0]}}",
        shell=True,
        executable="/bin/bash",
        capture_output=True,
        text=True,
        check=False,
    )
    assert "Traceback" not in proc.stderr, proc.stderr
    assert proc.returncode in (0, 1, 141)
