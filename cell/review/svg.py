"""Tiny inline-SVG plots for the HTML report (no JavaScript, no network, no library).

Every function returns an ``<svg>`` element as text; coordinates are in pixels of the drawing,
data are mapped linearly into the plot area.
"""

from __future__ import annotations

from collections.abc import Sequence
from html import escape

COLORS = {"conforming": "#2e7d32", "inconclusive": "#ef8f00", "nonconforming": "#c62828",
          None: "#757575"}  # fmt: skip
SERIES = ("#1565c0", "#6a1b9a", "#00838f", "#ad1457", "#558b2f", "#4e342e", "#37474f")


class Axes:
    """A linear map from data (x, y) to a plot area of ``width`` x ``height`` pixels."""

    def __init__(self, width: int, height: int, xlim, ylim, margin=(60, 20, 20, 40)) -> None:
        self.w, self.h = width, height
        self.left, self.right, self.top, self.bottom = margin
        x0, x1 = xlim
        y0, y1 = ylim
        self.xlim = (x0, x1 if x1 > x0 else x0 + 1.0)
        self.ylim = (y0, y1 if y1 > y0 else y0 + 1.0)

    def x(self, v: float) -> float:
        x0, x1 = self.xlim
        return self.left + (v - x0) / (x1 - x0) * (self.w - self.left - self.right)

    def y(self, v: float) -> float:
        y0, y1 = self.ylim
        return self.h - self.bottom - (v - y0) / (y1 - y0) * (self.h - self.top - self.bottom)


def svg(width: int, height: int, body: list[str], title: str) -> str:
    """Wrap drawing elements into an ``<svg>`` with an accessible title."""
    return (f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" '
            f'viewBox="0 0 {width} {height}" role="img" aria-label="{escape(title)}">'
            f"<title>{escape(title)}</title>{''.join(body)}</svg>")  # fmt: skip


def text(x: float, y: float, s: str, size: int = 11, anchor: str = "start", **kw) -> str:
    extra = "".join(f' {k.replace("_", "-")}="{v}"' for k, v in kw.items())
    return (f'<text x="{x:.1f}" y="{y:.1f}" font-size="{size}" text-anchor="{anchor}"'
            f'{extra}>{escape(s)}</text>')  # fmt: skip


def line(x1: float, y1: float, x2: float, y2: float, color="#000", width=1.0, dash="") -> str:
    d = f' stroke-dasharray="{dash}"' if dash else ""
    return (f'<line x1="{x1:.1f}" y1="{y1:.1f}" x2="{x2:.1f}" y2="{y2:.1f}" stroke="{color}" '
            f'stroke-width="{width}"{d}/>')  # fmt: skip


def frame(ax: Axes, xlabel: str, ylabel: str, xticks: Sequence[float],
          yticks: Sequence[float]) -> list[str]:  # fmt: skip
    """The plot's box, ticks and labels."""
    out = [f'<rect x="{ax.left}" y="{ax.top}" width="{ax.w - ax.left - ax.right}" '
           f'height="{ax.h - ax.top - ax.bottom}" fill="#fff" stroke="#999"/>']  # fmt: skip
    for t in xticks:
        out += [line(ax.x(t), ax.h - ax.bottom, ax.x(t), ax.h - ax.bottom + 4, "#666"),
                text(ax.x(t), ax.h - ax.bottom + 15, f"{t:g}", 10, "middle")]  # fmt: skip
    for t in yticks:
        out += [line(ax.left - 4, ax.y(t), ax.left, ax.y(t), "#666"),
                line(ax.left, ax.y(t), ax.w - ax.right, ax.y(t), "#eee"),
                text(ax.left - 6, ax.y(t) + 3, f"{t:g}", 10, "end")]  # fmt: skip
    out.append(text((ax.left + ax.w - ax.right) / 2, ax.h - 5, xlabel, 11, "middle"))
    yc = (ax.top + ax.h - ax.bottom) / 2
    out.append(text(14, yc, ylabel, 11, "middle", transform=f"rotate(-90 14 {yc:.1f})"))
    return out


def ticks(lo: float, hi: float, n: int = 5) -> list[float]:
    """About ``n`` round tick values covering [lo, hi]."""
    import math

    span = hi - lo if hi > lo else 1.0
    step = 10 ** math.floor(math.log10(span / n))
    for m in (1, 2, 5, 10):
        if span / (m * step) <= n:
            step *= m
            break
    first = math.ceil(lo / step) * step
    return [round(first + i * step, 10) for i in range(int((hi - first) / step) + 1)]


def text_box(x: float, y: float, s: str, size: int) -> tuple[float, float, float, float]:
    """The box ``(x0, y0, x1, y1)`` a left-anchored ``text`` at ``x``, ``y`` (its baseline)
    takes, estimated at 0.6 ``size`` per character."""
    return (x, y - 0.8 * size, x + 0.6 * size * len(s), y + 0.2 * size)


def _overlap(a: tuple[float, ...], b: tuple[float, ...]) -> bool:
    return a[0] < b[2] and b[0] < a[2] and a[1] < b[3] and b[1] < a[3]


def labels(points: Sequence[tuple[float, float]], names: Sequence[str], size: int = 8,
           fill: str = "#555") -> list[str]:  # fmt: skip
    """Text labels for the marks at ``points`` (px), each placed beside its mark where it
    overlaps no label placed before and no mark; when every spot near the mark is taken, a
    farther one with a leader line. Greedy, in the given order."""
    marks = [(x - 3, y - 3, x + 3, y + 3) for x, y in points]
    placed: list[tuple[float, float, float, float]] = []
    out = []
    for (x, y), s in zip(points, names, strict=True):
        w = 0.6 * size * len(s)
        near = [(4, -4), (4, size + 2), (-4 - w, -4), (-4 - w, size + 2), (-w / 2, -6),
                (-w / 2, size + 6)]  # fmt: skip
        far = [(r * dx - (w if dx < 0 else 0), r * dy) for r in (14, 22, 30, 40)
               for dx, dy in ((1, -1), (1, 1), (-1, -1), (-1, 1), (0, -1), (0, 1))]  # fmt: skip
        choice, leader = None, False
        for k, (dx, dy) in enumerate(near + far):
            box = text_box(x + dx, y + dy, s, size)
            if not any(_overlap(box, b) for b in placed + marks):
                choice, leader = (x + dx, y + dy), k >= len(near)
                break
        if choice is None:  # crowded beyond the search: the first spot, as before
            choice = (x + 4, y - 4)
        placed.append(text_box(*choice, s, size))
        if leader:
            out.append(line(x, y, choice[0] + w / 2, choice[1] - 0.3 * size, "#bbb", 0.6))
        out.append(text(choice[0], choice[1], s, size, fill=fill))
    return out
