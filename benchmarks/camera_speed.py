"""GigE Vision head speed on loopback: trigger-to-pair time and throughput for 5 MP pairs
(2448 x 2048 Mono8), through two Aravis fake cameras served in-process and the holecell client
(:class:`cell.camera.gige.GigeStereo`), against the simulator's TCP head on the same pairs.

    .venv/bin/python benchmarks/camera_speed.py [--pairs N]

Runs itself inside a private network namespace (``unshare -n``, as root): no packet leaves
loopback. The pairs are made once, so the times are the transport's and the checks', not the
renderer's. Prints one table: per transport and GVSP packet size, the time to open the head,
the trigger-to-pair time (median, 95th percentile, max) and the throughput.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

SHAPE = (2048, 2448)  # 5 MP, the standard head's sensor
ENV = "HOLECELL_IN_NETNS"


class Pairs:
    """Pre-made random pairs served in turn (a fixed render cost of zero)."""

    def __init__(self, n: int = 4) -> None:
        from cell.camera import StereoPair

        rng = np.random.default_rng(0)
        self.pairs = [StereoPair(*(rng.integers(0, 256, SHAPE, dtype=np.uint8) for _ in "lr"))
                      for _ in range(n)]  # fmt: skip
        self.k = 0

    def capture(self):
        self.k += 1
        return self.pairs[(self.k - 1) % len(self.pairs)]


def _measure(open_head, n: int) -> tuple[float, np.ndarray, int]:
    t0 = time.perf_counter()
    head = open_head()
    t_open = time.perf_counter() - t0
    try:
        head.capture()  # first pair: buffers allocated, caches warm
        times = []
        for _ in range(n):
            t = time.perf_counter()
            pair = head.capture()
            times.append(time.perf_counter() - t)
        retries = getattr(head, "retries", 0)
    finally:
        head.close()
    assert pair.left.shape == SHAPE
    return t_open, np.array(times), retries


def run(n: int) -> None:
    from cell.camera.aravis import aravis, clib
    from cell.camera.gige import GigeStereo
    from cell.camera.network import NetworkCamera
    from cell.sim.camserver import CameraServer
    from cell.sim.gige_head import GigeHead
    from measure.synth import standard_stereo

    aravis(), clib()  # the library loaded before anything is timed
    stereo = standard_stereo()
    rows = []
    with CameraServer(Pairs()).start() as srv:  # type: ignore[arg-type]
        tcp = _measure(lambda: NetworkCamera(srv.url, stereo), n)
        rows.append(("tcp:// (simulator)", "-", *tcp))
    for size in (1500, 8192, 9000):
        src = Pairs()
        with GigeHead(src.capture, SHAPE) as head:
            url = f"{head.url}?packet_size={size}"
            gige = _measure(lambda u=url: GigeStereo(u, stereo), n)
            rows.append(("gige:// (Aravis)", str(size), *gige))
    mb = 2 * SHAPE[0] * SHAPE[1] / 1e6
    print(
        f"\n5 MP stereo pairs ({mb:.1f} MB a pair) on loopback, {n} pairs each; load "
        f"average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores\n"
    )
    print(
        "| transport | packet size (B) | open (ms) | trigger-to-pair median / p95 / max (ms) "
        "| pairs/s | MB/s | retries |"
    )
    print("|---|---|---|---|---|---|---|")
    for name, size, t_open, t, retries in rows:
        med, p95, mx = np.median(t) * 1e3, np.percentile(t, 95) * 1e3, t.max() * 1e3
        rate = 1.0 / t.mean()
        print(
            f"| {name} | {size} | {t_open * 1e3:.0f} | {med:.0f} / {p95:.0f} / {mx:.0f} | "
            f"{rate:.1f} | {rate * mb:.0f} | {retries} |"
        )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--pairs", type=int, default=20)
    args = ap.parse_args()
    if os.environ.get(ENV) == "1":
        run(args.pairs)
        return
    root = Path(__file__).resolve().parents[1]
    cmd = (f"ip link set lo up && ip addr add 127.0.0.2/8 dev lo && exec {sys.executable} "
           f"{Path(__file__).resolve()} --pairs {args.pairs}")  # fmt: skip
    env = {**os.environ, ENV: "1", "PYTHONPATH": f"{root}:{os.environ.get('PYTHONPATH', '')}"}
    sys.exit(subprocess.run(["unshare", "-n", "sh", "-c", cmd], env=env).returncode)


if __name__ == "__main__":
    main()
