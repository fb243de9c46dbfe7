"""``spc.csv`` and ``spc.html`` of an SPC study (:mod:`cell.review.spc.stats`).

CSV: one row per characteristic, SI units (m): ``characteristic, kind, n, n_not_evaluated,
mean_m, s_m, sigma_within_m, mr_bar_m, lcl_m, ucl_m, ucl_mr_m, lsl_m, usl_m, cp, cpk, cpk_ci95_low,
cpk_ci95_high, capability_note, pp, ppk,
cpk_rice, out_of_control`` (``cpk_rice``: positions only, :mod:`cell.review.spc.bounded`;
the runs out of control as ``run:rule+rule`` separated by ``;``; empty cells where a figure
does not exist). HTML: the same table (``<table id="spc">``, one
``<tr class="char" data-char=NAME data-ooc=COUNT>`` per characteristic, values in um or mm as
the headers say), each characteristic's I and MR charts as inline SVG, and the list of runs.
"""

from __future__ import annotations

import csv
from dataclasses import dataclass
from html import escape
from pathlib import Path
from typing import Any

from cell.review.spc.bounded import RiceFit, rice_cpk
from cell.review.spc.chart import charts, unit
from cell.review.spc.collect import Series
from cell.review.spc.stats import (
    CAPABILITY_REFERENCE,
    MIN_CAPABILITY_N,
    RULES,
    Capability,
    capability,
)

COLUMNS = ("characteristic", "kind", "n", "n_not_evaluated", "mean_m", "s_m", "sigma_within_m",
           "mr_bar_m", "lcl_m", "ucl_m", "ucl_mr_m", "lsl_m", "usl_m", "cp", "cpk", "cpk_ci95_low",
           "cpk_ci95_high", "capability_note", "pp", "ppk",
           "cpk_rice", "out_of_control")  # fmt: skip
CSS = """body{font-family:Helvetica,Arial,sans-serif;margin:24px;color:#222;font-size:13px}
h1{font-size:20px}h2{font-size:15px;margin:22px 0 6px;border-bottom:1px solid #999}
table{border-collapse:collapse}td,th{border:1px solid #bbb;padding:2px 6px;text-align:right}
th{background:#eee}td.l,th.l{text-align:left}.bad{color:#c62828;font-weight:bold}
.note{color:#555;font-size:12px}svg{display:block;margin:4px 0}"""


@dataclass(frozen=True)
class Analysis:
    """A characteristic's series with its I-MR statistics (None and ``why`` when fewer than
    two values) and, for a position, its Rice fit."""

    series: Series
    cap: Capability | None
    rice: RiceFit | None = None
    why: str = ""


def analyse(all_series: list[Series]) -> list[Analysis]:
    """Each series with its statistics."""
    out = []
    for s in all_series:
        vals = [p.value_m for p in s.points if p.value_m is not None]
        if len(vals) < 2:
            out.append(
                Analysis(s, None, None, f"{len(vals)} evaluated run(s): statistics need two")
            )
        elif s.kind == "position":
            out.append(Analysis(s, capability(vals, s.lsl, s.usl, 0.0), rice_cpk(vals, s.usl)))
        else:
            out.append(Analysis(s, capability(vals, s.lsl, s.usl)))
    return out


def _ooc_runs(s: Series, cap: Capability) -> list[tuple[str, list[str]]]:
    runs = [p.run for p in s.points if p.value_m is not None]
    return [(runs[i], rules) for i, rules in sorted(cap.out_of_control.items())]


def csv_rows(results: list[Analysis]) -> list[dict[str, Any]]:
    """The rows of ``spc.csv``."""
    rows = []
    for a in results:
        s, cap = a.series, a.cap
        row: dict[str, Any] = {
            "characteristic": s.name,
            "kind": s.kind,
            "n": sum(p.value_m is not None for p in s.points),
            "n_not_evaluated": sum(p.value_m is None for p in s.points),
            "lsl_m": s.lsl,
            "usl_m": s.usl,
        }
        if cap is not None:
            row.update(
                mean_m=cap.mean,
                s_m=cap.s,
                sigma_within_m=cap.sigma_within,
                mr_bar_m=cap.mr_bar,
                lcl_m=cap.lcl,
                ucl_m=cap.ucl,
                ucl_mr_m=cap.ucl_mr,
                cp=cap.cp,
                cpk=cap.cpk,
                cpk_ci95_low=None if cap.cpk_ci95 is None else cap.cpk_ci95[0],
                cpk_ci95_high=None if cap.cpk_ci95 is None else cap.cpk_ci95[1],
                capability_note=cap.capability_note(),
                pp=cap.pp,
                ppk=cap.ppk,
                cpk_rice=None if a.rice is None else a.rice.cpk,
                out_of_control=";".join(
                    f"{Path(r).name}:{'+'.join(rules)}" for r, rules in _ooc_runs(s, cap)
                ),
            )
        rows.append(row)
    return rows


def _fmt(v: float | None, k: float = 1.0, digits: int = 2) -> str:
    return "" if v is None else f"{v * k:.{digits}f}"


def _table(results: list[Analysis]) -> str:
    head = ("characteristic", "kind", "unit", "n", "mean", "s", "σ̂ = MR̄/1.128", "LSL", "USL",
            "Cp", "Cpk", "Pp", "Ppk", "Cpk (Rice, percentile)", "runs out of control")  # fmt: skip
    rows = []
    for a in results:
        s, cap, why = a.series, a.cap, a.why
        k, u = unit(s.kind)
        digits = 1 if s.kind == "position" else 4
        n = sum(p.value_m is not None for p in s.points)
        if cap is None:
            note = f'<td class="l note" colspan="11">{escape(why)}</td>'
            cells = [escape(s.name), s.kind, u, str(n)]
            nooc = 0
        else:
            ooc = _ooc_runs(s, cap)
            nooc = len(ooc)
            cpk_cls = ' class="bad"' if cap.cpk is not None and cap.cpk < 1.33 else ""
            cells = [
                escape(s.name),
                s.kind,
                u,
                str(n),
                _fmt(cap.mean, k, digits),
                _fmt(cap.s, k, digits),
                _fmt(cap.sigma_within, k, digits),
                _fmt(s.lsl, k, digits) or "-",
                _fmt(s.usl, k, digits),
                _fmt(cap.cp) or "-",
                f"<span{cpk_cls}>{_fmt(cap.cpk) or '-'}</span>" + _cpk_ci(cap),
                _fmt(cap.pp) or "-",
                _fmt(cap.ppk) or "-",
                _fmt(None if a.rice is None else a.rice.cpk) or "-",
                ", ".join(f"{escape(Path(r).name)} ({', '.join(rules)})" for r, rules in ooc)
                or "none",
            ]
        tds = "".join(
            f"<td{' class=l' if i in (0, 1, 14) else ''}>{c}</td>" for i, c in enumerate(cells)
        ) + (note if cap is None else "")
        rows.append(f'<tr class="char" data-char="{escape(s.name)}" data-ooc="{nooc}">{tds}</tr>')
    ths = "".join(f"<th>{escape(h)}</th>" for h in head)
    return f'<table id="spc"><tr>{ths}</tr>{"".join(rows)}</table>'


def render_html(results: list[Analysis], runs: list[str]) -> str:
    """The self-contained ``spc.html`` page."""
    rules = "".join(f"<li>{escape(v)}</li>" for v in RULES.values())
    chart_html = "".join(
        f"<h2>{escape(a.series.name)}</h2>{charts(a.series, a.cap)}"
        for a in results
        if a.cap is not None
    )
    run_list = "".join(f"<li>{escape(r)}</li>" for r in runs)
    return f"""<!DOCTYPE html><html><head><meta charset="utf-8"><title>SPC: {len(runs)} runs
</title><style>{CSS}</style></head><body><h1>Statistical process control: {len(runs)} runs,
{len(results)} characteristics</h1>
<p class="note">Values from each run's report.qif (QIF 3.0), in run order. σ̂: moving-range
estimate MR̄/1.128 (control limits, Cp, Cpk); s: overall standard deviation (Pp, Ppk). Position:
one-sided, USL = the zone diameter without bonus, Cpk = (USL − mean)/3σ̂, no Cp; its values are
bounded at 0 and skewed, so a Rice fit gives the ISO 22514-2 percentile index
(USL − X50)/(X99.865 − X50) beside it. Cpk below 1.33 in red. From fewer than
{MIN_CAPABILITY_N} runs ({CAPABILITY_REFERENCE}) a Cpk is indicative only: its approximate 95 %
interval (Bissell) follows it, marked &#8224;. Rules for "out of control":</p>
<ul class="note">{rules}</ul>
{_table(results)}{chart_html}<h2>Runs</h2><ol class="note">{run_list}</ol></body></html>"""


def write_spc(results: list[Analysis], runs: list[str], out_dir: str | Path) -> tuple[Path, Path]:
    """Write ``spc.csv`` and ``spc.html`` into ``out_dir``; returns their paths."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    with (out / "spc.csv").open("w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=COLUMNS)
        w.writeheader()
        for row in csv_rows(results):
            w.writerow({k: ("" if row.get(k) is None else row.get(k, "")) for k in COLUMNS})
    (out / "spc.html").write_text(render_html(results, runs), encoding="utf-8")
    return out / "spc.csv", out / "spc.html"


def _cpk_ci(cap: Capability) -> str:
    """The Cpk's 95 % interval and a warning mark when the runs are too few for capability."""
    if cap.cpk_ci95 is None or cap.enough_for_capability:
        return ""
    lo, hi = cap.cpk_ci95
    title = escape(cap.capability_note())
    return f' <span class="note" title="{title}">[{lo:.2f}, {hi:.2f}]&#8224;</span>'
