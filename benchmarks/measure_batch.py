"""Start-up and per-pair cost of ``holecell measure``: one process per pair vs ``--pairs``.

Renders N standard 2448×2048 8-bit pairs (``measure.synth``) into a temporary folder
(``H01_left.png`` …), then times, as separate processes (``python -m cell.cli``, what the
``holecell`` script runs):

- ``holecell --help`` (the start-up floor: interpreter and CLI imports),
- ``holecell measure L R --stereo S --json`` for the first few pairs (one process per pair),
- ``holecell measure --pairs DIR --stereo S -o rows.csv`` for all N pairs (one process).

Wall-clock and CPU time (children's user + system, from ``resource``) per call; the
measurement's own time per pair comes from the rows (``time_s``). Usage:
``.venv/bin/python benchmarks/measure_batch.py [--pairs N]``.
"""

from __future__ import annotations

import argparse
import csv
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import cv2
import numpy as np

from measure.synth import RenderOptions, hole_in_view, render_hole_pair, standard_stereo

CLI = [sys.executable, "-m", "cell.cli"]


def _timed(cmd: list[str]) -> tuple[float, float, subprocess.CompletedProcess]:
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t = time.perf_counter()
    proc = subprocess.run(cmd, capture_output=True, text=True, check=False)
    wall = time.perf_counter() - t
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return wall, cpu, proc


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--pairs", type=int, default=20)
    ap.add_argument("--single", type=int, default=5, help="pairs measured one process each")
    args = ap.parse_args()
    st = standard_stereo()
    rng = np.random.default_rng(7)
    with tempfile.TemporaryDirectory() as tmp:
        d = Path(tmp) / "pairs"
        d.mkdir()
        stereo = Path(tmp) / "stereo.json"
        st.save(stereo)
        for k in range(args.pairs):
            c, n = hole_in_view(st, np.deg2rad(rng.uniform(0, 30)), rng.uniform(0, 2 * np.pi))
            r = render_hole_pair(st, c, n, rng.choice([0.006, 0.010, 0.0194]), RenderOptions(), k)
            cv2.imwrite(str(d / f"H{k + 1:02d}_left.png"), r.left)
            cv2.imwrite(str(d / f"H{k + 1:02d}_right.png"), r.right)
        helps = [_timed([*CLI, "--help"])[:2] for _ in range(3)]
        singles = []
        for k in range(min(args.single, args.pairs)):
            left, right = d / f"H{k + 1:02d}_left.png", d / f"H{k + 1:02d}_right.png"
            cmd = [*CLI, "measure", str(left), str(right), "--stereo", str(stereo), "--json"]
            wall, cpu, proc = _timed(cmd)
            if proc.returncode != 0:
                raise SystemExit(f"single measure failed: {proc.stdout}{proc.stderr}")
            singles.append((wall, cpu))
        rows_csv = Path(tmp) / "rows.csv"
        bw, bc, proc = _timed(
            [*CLI, "measure", "--pairs", str(d), "--stereo", str(stereo), "-o", str(rows_csv)]
        )
        if proc.returncode != 0:
            raise SystemExit(f"batch failed: {proc.stdout}{proc.stderr}")
        rows = list(csv.DictReader(rows_csv.open()))
    meas = np.array([float(r["time_s"]) for r in rows])
    hw, hc = np.median(np.array(helps), axis=0)
    sw, sc = np.median(np.array(singles), axis=0)
    n = len(rows)
    print(f"holecell measure: {n} standard 2448x2048 8-bit pairs, load average "
          f"{os.getloadavg()[0]:.1f} on this machine")  # fmt: skip
    print(f"{'call':<44} {'wall s':>8} {'cpu s':>8} {'per pair wall':>14} {'per pair cpu':>13}")
    print(f"{'holecell --help (start-up floor)':<44} {hw:8.2f} {hc:8.2f} {'':>14} {'':>13}")
    print(f"{'measure L R, one process per pair (median)':<44} {sw:8.2f} {sc:8.2f} "
          f"{sw:14.3f} {sc:13.3f}")  # fmt: skip
    print(f"{f'measure --pairs DIR ({n} pairs, one process)':<44} {bw:8.2f} {bc:8.2f} "
          f"{bw / n:14.3f} {bc / n:13.3f}")  # fmt: skip
    # batch = S + n p and single = S + p (S: start-up and calibration load, p: one pair)
    per_pair = (bc - sc) / max(n - 1, 1)
    startup = sc - per_pair
    print(f"measurement itself (rows' time_s): median {np.median(meas) * 1e3:.1f} ms, "
          f"total {meas.sum():.2f} s")  # fmt: skip
    print(f"derived (cpu): start-up and calibration load {startup:.2f} s per process; each pair "
          f"{per_pair * 1e3:.0f} ms (read two PNGs + measure)")  # fmt: skip
    print(f"{n} pairs: {n * sc:.1f} s cpu as separate calls vs {bc:.1f} s as one batch "
          f"({n * sc / bc:.1f}x)")  # fmt: skip


if __name__ == "__main__":
    main()
