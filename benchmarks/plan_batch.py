"""Benchmark of ``holecell plan-batch``: 20 generated variants, local multi-start, kill and resume.

Writes 20 variants of a cluttered instance (``benchmarks/cluttered_cells.py --variants``:
the same parts and holes, fixtures and clutter re-drawn) into a scratch folder, starts
``holecell plan-batch`` on them (default multi-start on the local cores) in a
subprocess, kills it (SIGKILL) once ``--kill-after`` cells are finished, runs the same
command again and checks that it skipped the finished cells and reported every tour.

Usage: ``python benchmarks/plan_batch.py [--variants 20] [--variant-of 20] [--kill-after 5]
[--dir DIR]``
"""

from __future__ import annotations

import argparse
import csv
import os
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).parent


def _finished(out: Path) -> int:
    path = out / "summary.csv"
    if not path.exists():
        return 0
    with path.open() as f:
        return sum(1 for _ in csv.DictReader(f))


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--variants", type=int, default=20)
    ap.add_argument("--variant-of", type=int, default=20)
    ap.add_argument("--kill-after", type=int, default=5)
    ap.add_argument("--dir", type=Path, default=None)
    args = ap.parse_args(argv)
    root = args.dir or Path(tempfile.mkdtemp(prefix="plan-batch-"))
    cells, out = root / "cells", root / "tours"
    subprocess.run(
        [sys.executable, str(HERE / "cluttered_cells.py"), "--variants", str(args.variants),
         "--variant-of", str(args.variant_of), "--out", str(cells)],
        check=True,
    )  # fmt: skip
    files = sorted(str(p) for p in cells.glob("*.yaml"))
    holecell = [sys.executable, "-m", "cell.cli", "plan-batch", *files, "-o", str(out)]
    print(f"{len(files)} variants in {cells}; load average {os.getloadavg()}")
    t = time.perf_counter()
    first = subprocess.Popen(holecell, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    while first.poll() is None and _finished(out) < args.kill_after:
        time.sleep(0.5)
    first.send_signal(signal.SIGKILL)
    first.wait()
    killed_at = _finished(out)
    t_first = time.perf_counter() - t
    t = time.perf_counter()
    second = subprocess.run(holecell, capture_output=True, text=True)
    t_second = time.perf_counter() - t
    with (out / "summary.csv").open() as f:
        rows = list(csv.DictReader(f))
    earlier = sum(r["planned"] == "earlier" for r in rows)
    tours = sum(Path(r["tour_file"]).exists() for r in rows if r["tour_file"])
    print(f"first run killed after {killed_at} finished cells ({t_first:.0f} s wall)")
    print(f"resumed run: exit {second.returncode}, {t_second:.0f} s wall, {earlier} skipped")
    print(second.stdout.strip())
    print("\n| cell | status | planned | holes | left out | cycle s | planning s (wall) |")
    print("|---|---|---|---|---|---|---|")
    for r in rows:
        print(
            f"| {Path(r['cell_file']).stem} | {r['status']} | {r['planned']} | {r['holes']} "
            f"| {r['left_out']} | {r['cycle_time_s']} | {r['planning_time_s']} |"
        )
    ok = len(rows) == len(files) and tours == len(files) and earlier >= killed_at
    print(f"\nevery variant has a tour: {tours}/{len(files)}; load average {os.getloadavg()}")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
