"""Progress display of a run for the CLI (``holecell run`` and ``holecell demo``): the run state
and a progress bar over the holes, on stderr. Not a subcommand (not in ``COMMAND_MODULES``)."""

from __future__ import annotations

import sys
from typing import TextIO

from cell.records.hole_result import HoleResult

WIDTH = 30


def bar(done: int, total: int, width: int = WIDTH) -> str:
    """``[#####.....]`` for ``done`` of ``total``."""
    n = round(width * done / total) if total else width
    return "[" + "#" * n + "." * (width - n) + "]"


class RunBars:
    """The ``progress(event, data)`` callback of :class:`cell.run.runner.Runner` for a terminal."""

    def __init__(self, total_holes: int, already: int = 0, stream: TextIO = sys.stderr) -> None:
        self.total = total_holes
        self.done = already
        self.refs = 0
        self.stream = stream
        self.tty = stream.isatty()

    def __call__(self, event: str, data: dict) -> None:
        if event == "state":
            self._end_line()
            msg = f"  ({data['message']})" if data.get("message") else ""
            print(f"run: {data['state']}{msg}", file=self.stream, flush=True)
        elif event == "reference":
            self.refs += 1
            self._draw(f"reference round {data['round'] + 1}: {self.refs} views measured")
        elif event == "hole":
            self.done += 1
            r: HoleResult = data["result"]
            dev = (  # ISO 1101 position (the zone's diameter), in the fixture frame: the
                # datum frame is known only when the report evaluates the run
                f"position ⌀{2 * r.position_deviation_m * 1e3:.4f} mm (fixture frame)"
                if r.position_deviation_m is not None
                else r.reason[:40]
            )
            if r.U_position_m is not None:
                dev += f" U ⌀{2 * r.U_position_m * 1e3:.4f} mm {r.decision or ''}"
            self._draw(f"holes {bar(self.done, self.total)} {self.done}/{self.total}  "
                       f"{r.hole_id:<8} {r.status:<7} {dev}")  # fmt: skip

    def _draw(self, text: str) -> None:
        if self.tty:
            print("\r\x1b[2K" + text, end="", file=self.stream, flush=True)
        else:
            print(text, file=self.stream, flush=True)

    def _end_line(self) -> None:
        if self.tty:
            print("", file=self.stream, flush=True)
