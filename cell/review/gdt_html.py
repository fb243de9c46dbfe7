"""The GD&T part of ``report.html``: alignment (datum reference frames, datum features, their
residuals, the placement), the characteristics table and the deviation plot in the datum
frame. Inline HTML and SVG only (no script, nothing from the network).

Tables a test reads back: ``<table id="drfs">`` (``<tr class="drf" data-drf=ID
data-status=...>``), ``<table id="placement">``, ``<table id="characteristics">`` (``<tr
class="char" data-char=ID data-decision=...>``).
"""

from __future__ import annotations

from html import escape
from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation

from cell.review.svg import Axes, frame, labels, line, svg, text, ticks

LABEL = {"conformance": "conformance proven", "nonconformance": "nonconformance proven",
         "inconclusive": "inconclusive", "not_evaluated": "not evaluated"}  # fmt: skip
CLASS = {"conformance": "conforming", "nonconformance": "nonconforming",
         "inconclusive": "inconclusive", "not_evaluated": ""}  # fmt: skip
COLOR = {"conformance": "#2e7d32", "nonconformance": "#c62828", "inconclusive": "#ef8f00",
         "not_evaluated": "#757575"}  # fmt: skip


def _um(v: float | None, digits: int = 1) -> str:
    return "" if v is None else f"{v * 1e6:.{digits}f}"


def _mm3(v: list[float] | None) -> str:
    return "" if v is None else " / ".join(f"{x * 1e3:.3f}" for x in v)


def _pose_text(pose: dict[str, Any] | None) -> tuple[str, str]:
    """(xyz in mm, rotation as roll / pitch / yaw in degrees) of a pose mapping."""
    if pose is None:
        return "", ""
    rpy = Rotation.from_quat(pose["quat_xyzw"]).as_euler("xyz", degrees=True)
    return _mm3(pose["xyz"]), " / ".join(f"{a:.4f}" for a in rpy)


def _drf_table(fields: dict[str, Any]) -> str:
    head = (
        "<tr><th class='l'>DRF</th><th class='l'>datums</th><th class='l'>status</th>"
        "<th>origin x / y / z in part (mm)</th><th>U (k=2) (µm)</th>"
        "<th>roll / pitch / yaw in part (deg)</th><th>U rotation (µrad)</th>"
        "<th class='l'>residuals of the datum fits (µm)</th><th class='l'>reason</th></tr>"
    )
    rows = []
    for d in fields["datum_reference_frames"]:
        xyz, rpy = _pose_text(d.get("T_part_drf"))
        U = d.get("U_T_part_drf") or {}
        res = ", ".join(f"{k} {v * 1e6:.1f}" for k, v in (d.get("residuals_m") or {}).items())
        label = " | ".join(d["datums"]) or d.get("kind", "")
        rows.append(f'<tr class="drf" data-drf="{escape(d["id"])}" data-status="{d["status"]}">'
                    f"<td class='l'>{escape(d['id'])}</td><td class='l'>{escape(label)}</td>"
                    f"<td class='l'>{d['status'].replace('_', ' ')}</td><td>{xyz}</td>"
                    f"<td>{' / '.join(_um(v) for v in U.get('xyz_m') or [])}</td><td>{rpy}</td>"
                    f"<td>{' / '.join(f'{v * 1e6:.0f}' for v in U.get('rotation_rad') or [])}"
                    f"</td><td class='l'>{res}</td>"
                    f"<td class='l'>{escape(d.get('reason', ''))}</td></tr>")  # fmt: skip
    datums = "".join(
        f"<tr><td class='l'>{escape(d['label'])}</td><td class='l'>{d['kind']}</td>"
        f"<td class='l'>{escape(', '.join(d['holes']))}</td>"
        f"<td class='l'>{'measured' if d['measured'] else 'NOT measured: ' + escape(d['reason'])}"
        f"</td></tr>" for d in fields["datums"])  # fmt: skip
    dt = (
        "<table id='datums'><tr><th class='l'>datum</th><th class='l'>kind</th>"
        f"<th class='l'>holes</th><th class='l'>measured</th></tr>{datums}</table>"
    )
    return f'<table id="drfs">{head}{"".join(rows)}</table><p></p>' + (dt if datums else "")


def _placement(fields: dict[str, Any]) -> str:
    p = fields.get("placement")
    if not p:
        return "<p>no placement: fewer than three holes measured</p>"
    if p["status"] != "evaluated":
        return (f"<table id='placement'><tr><td class='l'>not evaluated: "
                f"{escape(p['reason'])}</td></tr></table>")  # fmt: skip
    T = p["T_fixture_part"]
    xyz, rpy = _pose_text(T)
    angle = np.degrees(np.linalg.norm(Rotation.from_quat(T["quat_xyzw"]).as_rotvec()))
    dist = np.linalg.norm(T["xyz"]) * 1e3
    return ("<table id='placement'><tr><th class='l'>the part on its fixture</th>"
            "<th>x / y / z (mm)</th><th>U (k=2) (µm)</th><th>roll / pitch / yaw (°)</th>"
            "<th>U (µrad)</th><th>offset (mm)</th><th>angle (deg)</th></tr>"
            f"<tr><td class='l'>{escape(p['method'])}</td><td>{xyz}</td>"
            f"<td>{' / '.join(_um(v) for v in p['U_xyz_m'])}</td><td>{rpy}</td>"
            f"<td>{' / '.join(f'{v * 1e6:.0f}' for v in p['U_rotation_rad'])}</td>"
            f"<td>{dist:.3f}</td><td>{angle:.4f}</td></tr></table>")  # fmt: skip


def spec_text(c: dict[str, Any]) -> str:
    """A characteristic's zone (position) or limits (size), as HTML."""
    if c["kind"] == "position":
        mc = "" if c["material_condition"] == "RFS" else f" ({c['material_condition']})"
        ref = " | ".join(c["datums"]) or c["drf"]
        return f"&#8960;{c['zone_diameter_m'] * 1e3:.3f} mm{mc} to {escape(ref)}"
    return f"{c['upper_m'] * 1e6:+.0f} / {c['lower_m'] * 1e6:+.0f} µm"


def _char_table(fields: dict[str, Any]) -> str:
    head = ("<tr><th class='l'>characteristic</th><th>nominal (mm)</th>"
            "<th class='l'>zone or limits</th><th>actual (mm)</th>"
            "<th>deviation x / y / z in the DRF (µm)</th>"
            "<th>value (µm)</th><th>bonus (µm)</th><th>U (µm)</th><th class='l'>decision</th>"
            "<th class='l'>reason</th></tr>")  # fmt: skip
    rows = []
    for c in fields["characteristics"]:
        pos = c["kind"] == "position"
        nom = _mm3(c["nominal_m"]) if pos else f"&#8960;{c['nominal_m'] * 1e3:.3f}"
        act = (_mm3(c["actual_m"]) if pos else
               ("" if c["actual_m"] is None else f"{c['actual_m'] * 1e3:.4f}"))  # fmt: skip
        dev = (" / ".join(_um(v) for v in c["deviation_m"]) if pos and c["deviation_m"]
               else ("" if pos else _um(c["deviation_m"])))  # fmt: skip
        dec = c["decision"]
        rows.append(f'<tr class="char" data-char="{escape(c["id"])}" data-decision="{dec}">'
                    f"<td class='l'>{escape(c['id'])}</td><td>{nom}</td>"
                    f"<td class='l'>{spec_text(c)}</td><td>{act}</td><td>{dev}</td>"
                    f"<td>{_um(c['value_m']) if pos else ''}</td>"
                    f"<td>{_um(c.get('bonus_m')) if pos else ''}</td>"
                    f"<td class='U'>{_um(c['U_m'])}</td>"
                    f"<td class='l decision {CLASS[dec]}'>{LABEL[dec]}</td>"
                    f"<td class='l note'>{escape(c['reason'])}</td></tr>")  # fmt: skip
    return f'<table id="characteristics">{head}{"".join(rows)}</table>'


def _deviation_plot(fields: dict[str, Any]) -> str:
    """In-plane deviations (perpendicular to each hole's axis) of the position
    characteristics at their nominals, in the datum frame seen along its z (the primary
    datum's normal); arrows 0.5 px per µm, coloured by decision."""
    m = [c for c in fields["characteristics"] if c["kind"] == "position" and c["nominal_m"]
         and c["deviation_m"] is not None]  # fmt: skip
    W, H, per_um = 900, 520, 0.5
    if not m:
        return svg(W, 60, [text(10, 30, "no position evaluated")], "deviation in the datum frame")
    nom = np.array([c["nominal_m"] for c in m]) * 1e3
    pad = 60.0
    ax = Axes(W, H, (nom[:, 0].min() - pad, nom[:, 0].max() + pad),
              (nom[:, 1].min() - pad, nom[:, 1].max() + pad))  # fmt: skip
    body = frame(ax, "DRF x (mm)", "DRF y (mm)", ticks(*ax.xlim), ticks(*ax.ylim))
    for c, p in zip(m, nom, strict=True):
        x, y = ax.x(p[0]), ax.y(p[1])
        col = COLOR[c["decision"]]
        d = np.asarray(c["deviation_m"])
        a = np.asarray(c.get("axis_drf") or [0.0, 0.0, 1.0])
        d = (d - (d @ a) * a) * 1e6
        body.append(f'<circle cx="{x:.1f}" cy="{y:.1f}" r="2.5" fill="{col}"/>')
        body.append(line(x, y, x + per_um * d[0], y - per_um * d[1], col, 1.6))
    body += labels([(ax.x(p[0]), ax.y(p[1])) for p in nom], [c["hole_id"] for c in m])
    body.append(line(W - 190, 30, W - 140, 30, "#000", 1.6))
    body.append(text(W - 135, 34, "100 µm of deviation", 10))
    body.append(text(ax.left + 6, ax.top + 14, "in-plane deviation of each centre in the datum "
                     "frame, seen along the primary datum's normal", 10, fill="#555"))  # fmt: skip
    return svg(W, H, body, "deviation vectors in the datum reference frame")


def gdt_section(fields: dict[str, Any]) -> str:
    """The alignment, placement, characteristics and plot as HTML (report.json's fields)."""
    chars = fields["characteristics"]
    counts = {k: sum(c["decision"] == k for c in chars) for k in LABEL}
    summary = ", ".join(f"{v} {LABEL[k]}" for k, v in counts.items())
    return "\n".join([
        "<h2>Alignment: datum reference frames</h2>",
        f"<p>alignment of the run: <b>{escape(fields['alignment'])}</b> (fixture: the part frame "
        "of the cell file, part.base)</p>", _drf_table(fields),
        "<h2>Placement of the part on its fixture</h2>", _placement(fields),
        "<h2>Characteristics (GD&amp;T)</h2>",
        f"<p class='counts' id='char-counts'>{len(chars)} characteristics: {summary}</p>",
        _char_table(fields),
        "<p class='note'>Position: 2 &#8730;(dx&#178; + dy&#178;) perpendicular to the hole's "
        "nominal axis in the datum frame, at the hole's rim; U from a Monte Carlo over the "
        "measured centres and the alignment (GUM S1, 95 %). Size: the circle fit's diameter "
        "against its limits. Decisions per ISO 14253-1.</p>",
        "<h2>Deviations in the datum frame</h2>", _deviation_plot(fields),
    ])  # fmt: skip
