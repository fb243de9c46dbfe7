"""The individuals and moving-range charts of one characteristic as inline SVG
(:mod:`cell.review.svg` helpers). Position values (ISO 1101: the zone's diameter ⌀) in µm,
diameters in mm."""

from __future__ import annotations

import numpy as np

from cell.review.spc.collect import Series
from cell.review.spc.stats import Capability
from cell.review.svg import COLORS, Axes, frame, line, svg, text, ticks

WIDTH, HEIGHT = 640, 220


def unit(kind: str) -> tuple[float, str]:
    """(scale from m, label) of a characteristic kind's charts and table."""
    return (1e6, "µm") if kind == "position" else (1e3, "mm")


def _chart(
    x: np.ndarray,
    centre: float,
    lo: float | None,
    hi: float,
    limits: dict[str, float],
    flagged: set[int],
    title: str,
    ylabel: str,
) -> str:
    vals = [v for v in (*x, centre, hi, *(v for v in limits.values())) if v is not None]
    if lo is not None:
        vals.append(lo)
    y0, y1 = min(vals), max(vals)
    pad = 0.08 * (y1 - y0 or abs(y1) or 1.0)
    ax = Axes(WIDTH, HEIGHT, (0.5, len(x) + 0.5), (y0 - pad, y1 + pad), margin=(70, 110, 24, 36))
    n = len(x)
    xt = ticks(1, n, min(n, 10))
    body = frame(
        ax, "run", ylabel, [t for t in xt if float(t).is_integer()], ticks(y0 - pad, y1 + pad, 5)
    )
    body.append(text(ax.left, 15, title, 12, font_weight="bold"))
    for label, v, color, dash in (
        ("CL", centre, "#1565c0", ""),
        *(
            (
                k,
                v,
                "#c62828" if k.endswith("SL") else "#ef8f00",
                "6 3" if k.endswith("SL") else "3 3",
            )
            for k, v in limits.items()
        ),
    ):
        body.append(line(ax.left, ax.y(v), ax.w - ax.right, ax.y(v), color, 1.2, dash))
        body.append(text(ax.w - ax.right + 4, ax.y(v) + 3, f"{label} {v:.4g}", 10, fill=color))
    pts = " ".join(f"{ax.x(i + 1):.1f},{ax.y(v):.1f}" for i, v in enumerate(x))
    body.append(f'<polyline points="{pts}" fill="none" stroke="#555" stroke-width="1"/>')
    for i, v in enumerate(x):
        c = COLORS["nonconforming"] if i in flagged else "#1565c0"
        cls = "ooc" if i in flagged else "pt"
        body.append(
            f'<circle class="{cls}" cx="{ax.x(i + 1):.1f}" cy="{ax.y(v):.1f}" r="3.2" fill="{c}"/>'
        )
    return svg(WIDTH, HEIGHT, body, title)


def charts(s: Series, cap: Capability) -> str:
    """The I chart (with the tolerance limits) and the MR chart of ``s``."""
    k, u = unit(s.kind)
    x = np.array([p.value_m for p in s.points if p.value_m is not None]) * k
    limits = {"UCL": cap.ucl * k, "LCL": cap.lcl * k}
    if s.usl is not None:
        limits["USL"] = s.usl * k
    if s.lsl is not None:
        limits["LSL"] = s.lsl * k
    flagged = {i for i, rules in cap.out_of_control.items() if set(rules) - {"mr_beyond_ucl"}}
    i_chart = _chart(
        x,
        cap.mean * k,
        None,
        cap.ucl * k,
        limits,
        flagged,
        f"{s.name}: individuals",
        f"position ⌀ ({u}, ISO 1101)" if s.kind == "position" else f"{s.kind} ({u})",
    )
    mr = np.abs(np.diff(x))
    mr_flag = {i - 1 for i, rules in cap.out_of_control.items() if "mr_beyond_ucl" in rules}
    mr_chart = _chart(
        mr,
        cap.mr_bar * k,
        0.0,
        cap.ucl_mr * k,
        {"UCL": cap.ucl_mr * k},
        mr_flag,
        f"{s.name}: moving range",
        f"MR ({u})",
    )
    return i_chart + mr_chart
