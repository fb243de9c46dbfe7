"""The README's calibration steps, as written, on the simulated cell (issue 26, finding 1):
``holecell plan-calibration`` -> ``holecell sim`` (its own process) -> ``holecell calibrate cell
--tour`` -> ``holecell run --calibration``.

``plan-calibration`` offsets its views sideways twice as far as ``calibrate cell``'s own plan,
so the plate is often off the head's view axis; the simulated head must draw it wherever it is
in the image, as a real camera sees it. A short tour (12 views) of the three-hole cell.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

from cell_fixtures import SmallCell

from cell.calibration.file import load_calibration
from cell.cli import main

ROOT = Path(__file__).resolve().parents[2]


def _start_sim(cell: Path, log: Path) -> tuple[subprocess.Popen, str, str]:
    """``holecell sim CELL --transport socket`` in its own process; its two URLs."""
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    # an arm that has run for two hours: the calibration refuses one warming up by over 1 K
    # (the tour's simulated time grows with the machine's load: 0.3 K over 20 min at 2 h)
    argv = [sys.executable, "-m", "cell.cli", "sim", str(cell), "--transport", "socket",
            "--speed", "20", "--drift-offset-s", "7200", "--duration-s", "600"]  # fmt: skip
    out = log.open("w")
    proc = subprocess.Popen(argv, stdout=out, stderr=subprocess.STDOUT, env=env, cwd=ROOT)
    urls: dict[str, str] = {}
    for _ in range(1200):  # up to 120 s for the imports on a loaded machine
        for line in log.read_text().splitlines():
            parts = line.split()
            if len(parts) == 2 and parts[0] in ("controller", "camera"):
                urls[parts[0]] = parts[1]
        if len(urls) == 2 or proc.poll() is not None:
            break
        time.sleep(0.1)
    assert len(urls) == 2, log.read_text()
    return proc, urls["controller"], urls["camera"]


def test_the_readme_calibration_steps_run_on_the_simulator(
    small_cell: SmallCell, tmp_path: Path, capsys
) -> None:
    cell, caltour = str(small_cell.path), tmp_path / "caltour.json"
    assert main(["plan-calibration", cell, "--views", "12", "--criterion", "geometric",
                 "--quiet", "-o", str(caltour)]) == 0  # fmt: skip
    proc, port, camera = _start_sim(small_cell.path, tmp_path / "sim.log")
    try:
        capsys.readouterr()
        cellcal = tmp_path / "cellcal.json"
        code = main(["calibrate", "cell", cell, "--port", port, "--camera", camera,
                     "--tour", str(caltour), "-o", str(cellcal), "--quiet"])  # fmt: skip
        cap = capsys.readouterr()
        assert code == 0, cap.err
        assert "target not found" not in cap.err + cap.out
        cal = load_calibration(cellcal)
        # the simulator's default truth has no geometric error: the nominal hand-eye is found
        assert abs(cal.T_tool0_camera.T[2, 3] - 0.120) < 0.5e-3, cal.T_tool0_camera.T
        run_dir = tmp_path / "run"
        code = main(["run", str(small_cell.tour_path), "--cell", cell, "--port", port,
                     "--camera", camera, "--calibration", str(cellcal), "--out", str(run_dir),
                     "--reference-rounds", "0", "--settle-s", "0", "--no-record", "--yes",
                     "--quiet"])  # fmt: skip
        cap = capsys.readouterr()
        assert code == 0, cap.err
    finally:
        proc.send_signal(signal.SIGINT)
        try:
            proc.wait(timeout=30)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()
    report = json.loads((run_dir / "report.json").read_text())
    summary = report["summary"]
    assert summary["holes_measured"] == len(small_cell.cell.part.holes), summary
    assert summary["calibration"]["views"] == 12, summary["calibration"]
    assert all(h["u_cell_calibration_position_m"] > 0 for h in report["holes"])
