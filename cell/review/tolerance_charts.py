"""report.html's charts of each characteristic against its tolerance (inline SVG).

One row per characteristic, its mark coloured by that characteristic's own decision (not the
hole's): a position's ISO 1101 value ⌀ as a bar from 0 with its U (k = 2) and its limit (zone
plus bonus) drawn as a red tick; a diameter's signed deviation from nominal as a dot with its U
and both limits (lower and upper deviation: ISO 286 holes H8..H11 are one-sided, 0 and +t).
Marks carry ``class="mark" data-char=ID data-decision=...``, limits ``class="limit"``, the
zero line ``class="zero"`` (a test reads them back).

Without characteristics (a drawing that could not be evaluated) the holes' own old single
``tolerance`` t is charted: a zone of ⌀2t and a size of ±t (docs/gdt.md).
"""

from __future__ import annotations

from dataclasses import dataclass
from html import escape
from typing import Any

from cell.gdt.decide import CONFORMANCE, INDETERMINATE, NONCONFORMANCE, NOT_EVALUATED
from cell.records.hole_result import HoleResult
from cell.review.svg import Axes, frame, line, svg, text, ticks
from cell.uncertainty.decision import CONFORMING, INCONCLUSIVE, NONCONFORMING

COLOR = {CONFORMANCE: "#2e7d32", NONCONFORMANCE: "#c62828", INDETERMINATE: "#ef8f00",
         NOT_EVALUATED: "#757575"}  # fmt: skip
LIMIT_COLOR = "#c62828"
_FROM_HOLE = {CONFORMING: CONFORMANCE, NONCONFORMING: NONCONFORMANCE, INCONCLUSIVE: INDETERMINATE}


@dataclass(frozen=True)
class Item:
    """One characteristic's row: its value and U (m), its limits (m; None: none on that side)
    and its decision (:mod:`cell.gdt.decide` words)."""

    id: str
    label: str
    value_m: float | None
    U_m: float
    lower_m: float | None
    upper_m: float | None
    decision: str


def items(characteristics: list[dict[str, Any]], results: list[HoleResult],
          kind: str) -> list[Item]:  # fmt: skip
    """The rows of the ``kind`` chart (``position`` or ``diameter``)."""
    if characteristics:
        return [_item(c) for c in characteristics if c["kind"] == kind]
    out = []
    for r in results:
        if not r.measured or r.tolerance_m is None:
            continue
        t, dec = r.tolerance_m, _FROM_HOLE.get(r.decision or "", NOT_EVALUATED)
        if kind == "position":
            out.append(Item(f"{r.hole_id}.position", r.hole_id, 2 * r.position_deviation_m,
                            2 * (r.U_position_m or 0.0), None, 2 * t, dec))  # fmt: skip
        else:
            out.append(Item(f"{r.hole_id}.diameter", r.hole_id, r.diameter_deviation_m,
                            r.U_diameter_m or 0.0, -t, t, dec))  # fmt: skip
    return out


def _item(c: dict[str, Any]) -> Item:
    if c["kind"] == "position":
        return Item(c["id"], c["hole_id"], c["value_m"], c["U_m"] or 0.0, None,
                    c["zone_diameter_m"] + (c.get("bonus_m") or 0.0), c["decision"])  # fmt: skip
    return Item(c["id"], c["hole_id"], c["deviation_m"], c["U_m"] or 0.0, c["lower_m"],
                c["upper_m"], c["decision"])  # fmt: skip


def tolerance_chart(rows: list[Item], kind: str) -> str:
    """The chart of ``rows`` (µm): a position's ⌀ from 0, a diameter's signed deviation."""
    title = ("position ⌀ against its zone" if kind == "position"
             else "diameter deviation against its limits")  # fmt: skip
    W, row = 900, 13
    if not rows:
        return svg(W, 60, [text(10, 30, "no characteristic of this kind")], title)
    H = 70 + row * len(rows)
    um = [(v * 1e6 if v is not None else None) for v in (r.value_m for r in rows)]
    ends = [0.0]
    for r, v in zip(rows, um, strict=True):
        ends += [x * 1e6 for x in (r.lower_m, r.upper_m) if x is not None]
        if v is not None:
            ends += [v + r.U_m * 1e6] + ([] if kind == "position" else [v - r.U_m * 1e6])
    lo, hi = min(ends), max(ends)
    pad = 0.06 * (hi - lo or 1.0)
    lo = 0.0 if kind == "position" else lo - pad
    ax = Axes(W, H, (lo, hi + pad), (0.0, float(len(rows))), margin=(70, 20, 24, 35))
    xlabel = "position ⌀ (µm)" if kind == "position" else "diameter − nominal (µm)"
    body = frame(ax, xlabel, "", ticks(*ax.xlim), [])
    x0 = ax.x(0.0)
    body.append(
        f'<line class="zero" x1="{x0:.1f}" y1="{ax.top}" x2="{x0:.1f}" '
        f'y2="{H - ax.bottom}" stroke="#000" stroke-width="1"/>'
    )
    for i, (r, v) in enumerate(zip(rows, um, strict=True)):
        y0, y1 = ax.y(len(rows) - i), ax.y(len(rows) - i - 1)
        ym = (y0 + y1) / 2
        body.append(text(ax.left - 4, ym + 3, r.label, 8, "end"))
        for lim in (r.lower_m, r.upper_m):
            if lim is not None:
                xl = ax.x(lim * 1e6)
                body.append(f'<line class="limit" data-char="{escape(r.id)}" x1="{xl:.1f}" '
                            f'y1="{y0 + 1:.1f}" x2="{xl:.1f}" y2="{y1 - 1:.1f}" '
                            f'stroke="{LIMIT_COLOR}" stroke-width="2"/>')  # fmt: skip
        if v is None:
            body.append(text(ax.x(0.0) + 4, ym + 3, "not evaluated", 8, fill="#757575"))
            continue
        c, u = COLOR[r.decision], r.U_m * 1e6
        attrs = f'class="mark" data-char="{escape(r.id)}" data-decision="{r.decision}"'
        if kind == "position":
            body.append(f'<rect {attrs} x="{x0:.1f}" y="{y0 + 2:.1f}" '
                        f'width="{max(ax.x(v) - x0, 0.5):.1f}" height="{max(y1 - y0 - 4, 1):.1f}" '
                        f'fill="{c}" opacity="0.75"/>')  # fmt: skip
        else:
            body.append(f'<circle {attrs} cx="{ax.x(v):.1f}" cy="{ym:.1f}" r="3" fill="{c}"/>')
        a = max(v - u, 0.0) if kind == "position" else v - u  # a position is never negative
        body += [line(ax.x(a), ym, ax.x(v + u), ym, "#000", 1.2),
                 line(ax.x(a), ym - 3, ax.x(a), ym + 3, "#000", 1.2),
                 line(ax.x(v + u), ym - 3, ax.x(v + u), ym + 3, "#000", 1.2)]  # fmt: skip
    body += _legend(W, kind)
    return svg(W, H, body, f"{title}, with U (k = 2)")


def _legend(W: int, kind: str) -> list[str]:
    """Limit tick, U bar and the decision colours, above the plot."""
    out = [f'<line x1="{W - 520}" y1="10" x2="{W - 520}" y2="20" stroke="{LIMIT_COLOR}" '
           'stroke-width="2"/>', text(W - 514, 19, "limit" if kind == "diameter"
                                      else "limit (zone + bonus)", 10),
           line(W - 400, 15, W - 380, 15, "#000", 1.2), text(W - 375, 19, "± U", 10)]  # fmt: skip
    x = W - 330
    for dec, word in ((CONFORMANCE, "conformance proven"), (INDETERMINATE, "inconclusive"),
                      (NONCONFORMANCE, "nonconformance proven")):  # fmt: skip
        out += [
            f'<rect x="{x}" y="10" width="9" height="9" fill="{COLOR[dec]}"/>',
            text(x + 12, 19, word, 10),
        ]
        x += 18 + int(5.5 * len(word))
    return out
