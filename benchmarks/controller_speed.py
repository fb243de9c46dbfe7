"""The Python controller against the shipped RAPID module in the interpreter: time to load a
trajectory and the STATUS round trip, over a pty and a socket.

    .venv/bin/python benchmarks/controller_speed.py [--rows 200 2000]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from cell.link.client import ControllerClient, LinkOptions
from cell.sim.controller import SimController
from cell.sim.rapid_controller import RapidController
from cell.sim.server import SimServer
from cell.sim.world import SimClock

HOME = np.array([0.0, -0.3, 0.4, 0.0, 0.5, 0.0])
LINK = LinkOptions(response_timeout_s=0.5, retries=20, heartbeat_period_s=0.25)


def _trajectory(n: int) -> np.ndarray:
    s = np.linspace(0.0, 1.0, n)[:, None]
    return HOME + np.sin(np.pi * s) * np.array([2.6, 0.2, -0.1, 3.5, 0.3, -6.0])


def _server(controller: str, transport: str):
    temps = lambda t: np.full(6, 25.0)  # noqa: E731
    if controller == "rapid":
        return RapidController(SimClock(50.0), temps, "abb_test", HOME, transport=transport)
    return SimServer(SimController(SimClock(50.0), temps, "abb_test", HOME), None, transport)


def measure(controller: str, transport: str, rows: int) -> list[object]:
    q = _trajectory(rows)
    t0 = time.perf_counter()
    with _server(controller, transport).start() as sim, ControllerClient(sim.url, LINK) as c:
        t_start = time.perf_counter() - t0
        t = time.perf_counter()
        c.load_trajectory(q, [rows // 2], 0.004)
        t_load = time.perf_counter() - t
        trips = []
        for _ in range(50):
            t = time.perf_counter()
            c.status()
            trips.append(time.perf_counter() - t)
        retrans = c.stats.retransmits
    ms = np.array(trips) * 1e3
    return [controller, transport, rows, f"{t_start:.2f}", f"{t_load:.2f}",
            f"{np.median(ms):.1f}", f"{np.percentile(ms, 95):.1f}", retrans]  # fmt: skip


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rows", type=int, nargs="+", default=[200, 2000])
    args = ap.parse_args()
    head = ["controller", "transport", "rows", "start s", "load s", "STATUS ms", "p95 ms",
            "retransmits"]  # fmt: skip
    rows = [measure(c, tr, n) for n in args.rows for tr in ("pty", "socket")
            for c in ("python", "rapid")]  # fmt: skip
    widths = [max(len(str(x)) for x in col) for col in zip(head, *rows, strict=True)]
    print("  ".join(f"{h:>{w}}" for h, w in zip(head, widths, strict=True)))
    for r in rows:
        print("  ".join(f"{x!s:>{w}}" for x, w in zip(r, widths, strict=True)))


if __name__ == "__main__":
    main()
