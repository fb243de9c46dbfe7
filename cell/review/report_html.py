"""``report.html``: the inspection protocol of a run, one self-contained file.

A CMM-style report: a header (cell, part, run, dates, operator, temperatures, decision rule),
the counts, one table row per hole (nominal, actual, position ⌀, U, tolerance, decision), plots
as inline SVG (deviation vectors over the part, each characteristic against its tolerance with
U: :mod:`cell.review.tolerance_charts`, the thermal state over the run) and the uncertainty
budget. No script, no stylesheet or font from the network: it opens and prints anywhere.
Lengths shown in mm and µm (the headers say which); positions and diameters at 20 °C.

The hole table is ``<table id="holes">`` with one ``<tr class="hole" data-hole=ID
data-decision=...>`` per planned hole (a test reads it back with :mod:`html.parser`).
"""

from __future__ import annotations

import time
from html import escape
from typing import Any

import numpy as np

from cell.calibration.use import describe
from cell.records.hole_result import HoleResult
from cell.review.gdt_html import spec_text
from cell.review.svg import COLORS, SERIES, Axes, frame, labels, line, svg, text, ticks
from cell.review.tolerance_charts import items, tolerance_chart
from cell.uncertainty.budget import COMPONENTS

DECISION_LABEL = {"conforming": "conformance proven", "inconclusive": "inconclusive",
                  "nonconforming": "nonconformance proven", None: "-"}  # fmt: skip
CSS = """
body{font-family:Helvetica,Arial,sans-serif;margin:24px;color:#222;font-size:13px}
h1{font-size:20px;margin:0 0 4px}h2{font-size:15px;margin:22px 0 6px;border-bottom:1px solid #999}
table{border-collapse:collapse}td,th{border:1px solid #bbb;padding:2px 6px;text-align:right}
th{background:#eee}td.l,th.l{text-align:left}
.hdr td{text-align:left;border:none;padding:1px 12px 1px 0}
.conforming{color:#2e7d32;font-weight:bold}.inconclusive{color:#b36b00;font-weight:bold}
.nonconforming{color:#c62828;font-weight:bold}.note{color:#555;font-size:12px}
.counts span{display:inline-block;margin-right:18px;font-size:14px}
"""


def _fmt(v: float | None, scale: float, digits: int) -> str:
    return "" if v is None else f"{v * scale:.{digits}f}"


def _date(t: float | None) -> str:
    return "-" if t is None else time.strftime("%Y-%m-%d %H:%M:%S UTC", time.gmtime(t))


def _header(summ: dict[str, Any], info: dict[str, Any], operator: str,
            results: list[HoleResult]) -> str:  # fmt: skip
    part = summ.get("part") or {}
    temps = np.array([r.temperatures_c for r in results if r.temperatures_c], float)
    arm = (f"{temps.min():.1f} .. {temps.max():.1f} °C over {temps.shape[1]} sensors"
           if temps.size else "-")  # fmt: skip
    ptemp = (f"{part['temperature_c']:.2f} °C ± {part['u_temperature_K']:.2f} K "
             f"({part['source']}); {part['material']}, alpha {part['alpha_per_K'] * 1e6:.2f} "
             f"± {part['u_alpha_per_K'] * 1e6:.2f} ppm/K" if part else "-")  # fmt: skip
    rows = [("Cell", f"{summ['cell']} (SHA-256 {summ['cell_sha256'][:12]})"),
            ("Part", f"{len(results)} of {summ['holes_planned']} holes stored"),
            ("Robot", summ["robot_model"]), ("Run", info.get("run_dir", "")),
            ("Cell file", info.get("cell_path", "")),
            ("Run state", summ["state"]), ("Started", _date(summ["started_at"])),
            ("Finished", _date(summ["finished_at"])),
            ("Operator", operator or "_" * 28 + "   signature " + "_" * 20),
            ("Part temperature", ptemp), ("Arm temperatures", arm),
            ("Cell calibration", describe(summ.get("calibration"))),
            ("Reference temperature", "20 °C (ISO 1): every position and diameter is reported "
                                      "at 20 °C"),
            ("Decision rule", (summ.get("decision_rule") or "-") + " (ISO 14253-1: conformance "
             "proven when |deviation| + U <= tolerance; U expanded, k = 2)")]  # fmt: skip
    body = "".join(f"<tr><td><b>{escape(k)}</b></td><td>{escape(str(v))}</td></tr>"
                   for k, v in rows)  # fmt: skip
    return f'<table class="hdr">{body}</table>'


def _counts(summ: dict[str, Any]) -> str:
    items = [("measured", summ["holes_measured"]), ("missing", summ["holes_missing"]),
             ("not measurable", summ["holes_unmeasured"]),
             ("not reached", summ["holes_not_reached"]),
             ("conformance proven", summ["holes_conforming"]),
             ("inconclusive", summ["holes_inconclusive"]),
             ("nonconformance proven", summ["holes_nonconforming"])]  # fmt: skip
    return '<p class="counts">' + "".join(
        f'<span id="count-{k.replace(" ", "-")}">{escape(k)}: <b>{v}</b></span>' for k, v in items
    ) + "</p>"  # fmt: skip


def _tolerances(chars: list[dict[str, Any]], results: list[HoleResult]) -> dict[str, str]:
    """The tolerance column per hole: its characteristics' zones and limits (the old single
    ``tolerance`` t as a zone of ⌀2t and a size of ±t when there are none)."""
    out: dict[str, list[str]] = {}
    for c in chars:
        out.setdefault(c["hole_id"], []).append(spec_text(c))
    for r in results:
        if r.hole_id not in out and r.tolerance_m is not None:
            t = r.tolerance_m
            out[r.hole_id] = [f"&#8960;{2 * t * 1e3:.3f} mm", f"±{t * 1e6:.0f} µm"]
    return {k: "; ".join(v) for k, v in out.items()}


def _hole_table(results: list[HoleResult], planned: list[tuple[str, int, dict]],
                tolerance: dict[str, str]) -> str:  # fmt: skip
    head = ("<tr><th class='l'>hole</th><th>stop</th><th>nominal x / y / z (mm)</th>"
            "<th>actual x / y / z (mm)</th><th>position &#8960; (µm)</th>"
            "<th>U pos. &#8960; (µm)</th>"
            "<th>nominal dia. (mm)</th><th>actual dia. (mm)</th><th>dia. dev. (µm)</th>"
            "<th>U dia. (µm)</th><th class='l'>tolerance</th><th class='l'>decision</th>"
            "<th class='l'>status</th></tr>")  # fmt: skip
    by_id = {r.hole_id: r for r in results}
    rows = []
    for hole_id, stop, nominal in planned:
        r = by_id.get(hole_id)
        nom = nominal.get("position_part_m") or (r.nominal_part_m if r else None)
        nom_s = " / ".join(f"{v * 1e3:.3f}" for v in nom) if nom else ""
        if r is None:
            rows.append(f'<tr class="hole" data-hole="{escape(hole_id)}" data-decision="">'
                        f"<td class='l'>{escape(hole_id)}</td><td>{stop}</td><td>{nom_s}</td>"
                        + "<td></td>" * 7 + f"<td class='l'>{tolerance.get(hole_id, '')}</td>"
                        + "<td></td><td class='l'>not reached</td></tr>")  # fmt: skip
            continue
        act = " / ".join(f"{v * 1e3:.3f}" for v in r.center_part_m) if r.center_part_m else ""
        dec = r.decision
        cls = dec or ""
        status = r.status + (f": {r.reason}" if r.reason else "")
        rows.append(
            f'<tr class="hole" data-hole="{escape(r.hole_id)}" data-decision="{cls}">'
            f"<td class='l'>{escape(r.hole_id)}</td><td>{r.stop_index}</td><td>{nom_s}</td>"
            f"<td>{act}</td><td>{_fmt(r.position_deviation_m, 2e6, 1)}</td>"
            f"<td class='U'>{_fmt(r.U_position_m, 2e6, 1)}</td>"
            f"<td>{_fmt(r.nominal_diameter_m, 1e3, 3)}</td><td>{_fmt(r.diameter_m, 1e3, 4)}</td>"
            f"<td>{_fmt(r.diameter_deviation_m, 1e6, 1)}</td>"
            f"<td class='U'>{_fmt(r.U_diameter_m, 1e6, 1)}</td>"
            f"<td class='l'>{tolerance.get(r.hole_id, '')}</td>"
            f"<td class='l decision {cls}'>{DECISION_LABEL.get(dec, dec)}</td>"
            f"<td class='l'>{escape(status)}</td></tr>")  # fmt: skip
    return f'<table id="holes">{head}{"".join(rows)}</table>'


def _in_plane(r: HoleResult) -> np.ndarray:
    """The centre's deviation without its axial part (part frame, m)."""
    delta = np.subtract(r.center_part_m, r.nominal_part_m)
    if r.axial_deviation_m is None or r.normal_part is None:
        return delta
    return delta - r.axial_deviation_m * np.asarray(r.normal_part, float)


def _vector_plot(results: list[HoleResult]) -> str:
    """Deviation vectors over the part: side view (part x, z), arrows magnified."""
    m = [r for r in results if r.measured]
    W, H = 900, 420
    if not m:
        return svg(W, 60, [text(10, 30, "no measured hole")], "deviation vectors")
    nom = np.array([r.nominal_part_m for r in m]) * 1e3
    dev = np.array([_in_plane(r) for r in m]) * 1e6
    pad = 40.0
    ax = Axes(W, H, (nom[:, 0].min() - pad, nom[:, 0].max() + pad),
              (nom[:, 2].min() - pad, nom[:, 2].max() + pad))  # fmt: skip
    per_um = 1.0  # arrow length: 1 px per µm
    body = frame(ax, "part x (mm)", "part z (mm)", ticks(*ax.xlim), ticks(*ax.ylim))
    for r, p, d in zip(m, nom, dev, strict=True):
        x, y = ax.x(p[0]), ax.y(p[2])
        c = COLORS.get(r.decision, "#757575")
        body.append(f'<circle cx="{x:.1f}" cy="{y:.1f}" r="3" fill="{c}"/>')
        body.append(line(x, y, x + per_um * d[0], y - per_um * d[2], c, 1.6))
    body += labels([(ax.x(p[0]), ax.y(p[2])) for p in nom], [r.hole_id for r in m])
    body.append(line(W - 180, 30, W - 130, 30, "#000", 1.6))
    body.append(text(W - 125, 34, "50 µm of deviation", 10))
    body.append(text(ax.left + 6, ax.top + 14, "in-plane deviation of each hole, seen from the "
                     "robot's side (part y toward the viewer)", 10, fill="#555"))  # fmt: skip
    return svg(W, H, body, "deviation vectors over the part (side view, x-z)")


def _thermal_plot(results: list[HoleResult], reference: list[tuple[float, Any]]) -> str:
    """Sensor readings over the run's controller time (reference rounds and holes), the
    inspection window shaded, and the thermal compensation applied."""
    m = [r for r in results if r.temperatures_c]
    W, H = 900, 300
    if not m and not reference:
        return svg(W, 60, [text(10, 30, "no temperatures recorded")], "thermal drift")
    rows = sorted([(float(t), np.asarray(T, float)) for t, T in reference]
                  + [(r.sim_time_s, np.asarray(r.temperatures_c, float)) for r in m],
                  key=lambda x: x[0])  # fmt: skip
    t = np.array([a for a, _ in rows]) / 60.0
    temps = np.array([b for _, b in rows])
    ax = Axes(W, H, (t.min(), t.max() if t.max() > t.min() else t.min() + 1),
              (temps.min() - 0.5, temps.max() + 0.5), margin=(60, 220, 20, 40))  # fmt: skip
    body = frame(ax, "controller time (min)", "sensor reading (°C)", ticks(*ax.xlim),
                 ticks(*ax.ylim))  # fmt: skip
    if m:
        t0, t1 = min(r.sim_time_s for r in m) / 60.0, max(r.sim_time_s for r in m) / 60.0
        body.append(
            f'<rect x="{ax.x(t0):.1f}" y="{ax.top}" width="{max(ax.x(t1) - ax.x(t0), 2):.1f}" '
            f'height="{ax.h - ax.top - ax.bottom}" fill="#1565c0" opacity="0.08"/>'
        )
        body.append(text(ax.x(t0) - 4, ax.top + 12, "holes", 10, "end", fill="#1565c0"))
    for j in range(temps.shape[1]):
        pts = " ".join(f"{ax.x(a):.1f},{ax.y(b):.1f}" for a, b in zip(t, temps[:, j], strict=True))
        c = SERIES[j % len(SERIES)]
        body.append(f'<polyline points="{pts}" fill="none" stroke="{c}" stroke-width="1.5"/>')
        body.append(text(W - 210, 30 + 14 * j, f"sensor {j + 1}", 10, fill=c))
    comp = [np.linalg.norm(np.subtract(r.center_part_m, r.extra["center_part_uncompensated_m"]))
            for r in m if r.measured and "center_part_uncompensated_m" in r.extra]  # fmt: skip
    if comp:
        lo, hi = np.min(comp) * 1e6, np.max(comp) * 1e6
        body.append(text(W - 210, 40 + 14 * temps.shape[1],
                         f"compensation applied: {lo:.0f}..{hi:.0f} µm", 10))  # fmt: skip
    return svg(W, H, body, "thermal state over the run")


def _budget_table(results: list[HoleResult]) -> str:
    rows = {c: ([], []) for c in COMPONENTS}
    notes: dict[str, str] = {}
    for r in results:
        for c in (r.budget or {}).get("components", []):
            rows.setdefault(c["name"], ([], []))
            rows[c["name"]][0].append(c["u_position_m"])
            rows[c["name"]][1].append(c["u_diameter_m"])
            notes[c["name"]] = c["note"]
    head = (
        "<tr><th class='l'>component</th><th>u position (in-plane), median / max (µm)</th>"
        "<th>u diameter, median / max (µm)</th><th class='l'>source</th></tr>"
    )
    body = []
    for name, (p, d) in rows.items():
        if not p:
            continue
        body.append(f"<tr><td class='l'>{escape(name)}</td>"
                    f"<td>{np.median(p) * 1e6:.2f} / {np.max(p) * 1e6:.2f}</td>"
                    f"<td>{np.median(d) * 1e6:.2f} / {np.max(d) * 1e6:.2f}</td>"
                    f"<td class='l note'>{escape(notes.get(name, ''))}</td></tr>")  # fmt: skip
    if not body:
        return "<p>no budget stored (a run from before the uncertainty budget)</p>"
    return f'<table id="budget">{head}{"".join(body)}</table>'


def render_html(summ: dict[str, Any], info: dict[str, Any], results: list[HoleResult],
                planned: list[tuple[str, int, dict]], operator: str = "",
                reference: list[tuple[float, Any]] | None = None,
                gdt_html: str = "", fixture_plot: bool = True,
                characteristics: list[dict[str, Any]] | None = None,
                referencing_html: str = "") -> str:  # fmt: skip
    """The whole ``report.html`` document; ``reference``: (controller time s, readings degC)
    of the reference-target observations, for the thermal plot; ``gdt_html``: the alignment
    and characteristics (:mod:`cell.review.gdt_html`), after the counts; ``fixture_plot``: draw the
    deviation vectors in the part frame (False when the run is evaluated in a datum frame,
    whose own plot ``gdt_html`` holds); ``characteristics``: report.json's, for the tolerance
    column and charts (none: the holes' old single tolerance); ``referencing_html``: the marker
    network and each stop's referencing (:mod:`cell.review.referencing_html`), after the
    budget."""
    chars = characteristics or []
    parts = [
        "<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'>",
        f"<title>Inspection report {escape(summ['cell'])}</title><style>{CSS}</style></head><body>",
        f"<h1>Inspection report: {escape(summ['cell'])}</h1>",
        _header(summ, info, operator, results),
        "<h2>Result</h2>", _counts(summ), gdt_html,
        "<h2>Holes</h2>", _hole_table(results, planned, _tolerances(chars, results)),
        "<p class='note'>Position &#8960; (ISO 1101): the diameter of the zone about the "
        "nominal axis that holds the measured centre, 2 &#215; its distance from the nominal in "
        "the plane perpendicular to the nominal axis, in the run's alignment (above; the "
        "positions are in the part frame). U: expanded uncertainty (k = 2). Decisions per "
        "ISO 14253-1 on both characteristics.</p>",
        *(["<h2>Deviation vectors over the part</h2>", _vector_plot(results)]
          if fixture_plot else []),
        "<h2>Position &#8960; against the tolerance</h2>",
        tolerance_chart(items(chars, results, "position"), "position"),
        "<h2>Diameter deviation against the tolerance</h2>",
        tolerance_chart(items(chars, results, "diameter"), "diameter"),
        "<h2>Thermal drift over the run</h2>", _thermal_plot(results, reference or []),
        "<h2>Uncertainty budget (standard uncertainties, GUM)</h2>", _budget_table(results),
        referencing_html,
        f"<p class='note'>written {_date(time.time())} by holecell</p></body></html>",
    ]  # fmt: skip
    return "\n".join(parts)
