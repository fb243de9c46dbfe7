"""The referencing section of ``report.html``: the surveyed marker network, the survey's
figures, and per stop whether it was located against the markers, by which, and how far the
arm's idea of the head was from it."""

from __future__ import annotations

from html import escape
from typing import Any

import numpy as np

from cell.records.hole_result import HoleResult
from cell.review.svg import Axes, frame, svg, text, ticks


def _network_plot(doc: dict[str, Any], used: set[str]) -> str:
    """The markers seen from the robot (cell y across, z up), dot size by their survey sigma."""
    ids = [m["id"] for m in doc["markers"]]
    P = np.array([m["position_m"] for m in doc["markers"]], float) * 1e3
    C = np.asarray(doc["covariance_m2"], float)
    sig = np.sqrt(np.clip(np.diag(C), 0.0, None)).reshape(-1, 3)
    s_um = np.linalg.norm(sig, axis=1) * 1e6
    W, H, pad = 900, 420, 60.0
    ax = Axes(W, H, (P[:, 1].min() - pad, P[:, 1].max() + pad),
              (P[:, 2].min() - pad, P[:, 2].max() + pad))  # fmt: skip
    body = frame(ax, "cell y (mm)", "cell z (mm)", ticks(*ax.xlim), ticks(*ax.ylim))
    for mid, p, s in zip(ids, P, s_um, strict=True):
        color = "#1565c0" if mid in used else "#9e9e9e"
        r = 2.0 + min(float(s), 30.0) / 3.0
        body.append(f'<circle cx="{ax.x(p[1]):.1f}" cy="{ax.y(p[2]):.1f}" r="{r:.1f}" '
                    f'fill="{color}" fill-opacity="0.6"><title>{escape(mid)}: sigma '
                    f'{s:.1f} um</title></circle>')  # fmt: skip
    body.append(text(ax.left + 6, ax.top + 14, "markers seen from the robot; blue: used by a "
                     "stop; dot size grows with the survey's sigma (hover: id, sigma)", 10,
                     fill="#555"))  # fmt: skip
    return svg(W, H, body, "surveyed marker network (cell y-z)")


def _figures(doc: dict[str, Any]) -> str:
    f, sc = doc.get("figures", {}), doc.get("scale", {})
    C = np.asarray(doc["covariance_m2"], float)
    s = np.linalg.norm(np.sqrt(np.clip(np.diag(C), 0.0, None)).reshape(-1, 3), axis=1) * 1e6
    rows = [
        ("surveyed", f"{escape(str(doc.get('created_utc')))}, {len(doc['markers'])} markers, "
                     f"{f.get('views')} views, {f.get('observations')} observations"),
        ("image residuals", f"{f.get('rms_px', float('nan')):.3f} px RMS, variance factor "
                            f"{f.get('variance_factor', float('nan')):.2f}"),
        ("marker sigma", f"median {np.median(s):.1f} µm, largest {s.max():.1f} µm"),
        ("scale", f"σ {sc.get('sigma_ppm', float('nan')):.1f} ppm "
                  f"({escape(str(sc.get('source', '')))})"),
        ("gauge", escape(str(doc.get("gauge", "")))),
        *(("warning", escape(w)) for w in doc.get("warnings", [])),
    ]  # fmt: skip
    return ("<table>" + "".join(f"<tr><th>{k}</th><td>{v}</td></tr>" for k, v in rows)
            + "</table>")  # fmt: skip


def _stops(results: list[HoleResult]) -> str:
    head = ("<tr><th>hole</th><th>referenced</th><th>markers used</th><th>refused</th>"
            "<th>arm vs markers (mm)</th><th>resection RMS (px)</th></tr>")  # fmt: skip
    body = []
    for r in results:
        ref = r.extra.get("referencing")
        if ref is None:
            continue
        refused = "; ".join(f"{k}: {v}" for k, v in ref.get("refused", {}).items())
        if ref.get("referenced"):
            d = ref.get("arm_disagreement_m", float("nan")) * 1e3
            flag = " style='color:#c62828'" if d > 1.0 else ""
            cells = (
                "yes",
                " ".join(ref.get("markers", [])),
                refused,
                f"<span{flag}>{d:.3f}</span>",
                f"{ref.get('rms_px', float('nan')):.3f}",
            )
        else:
            why = escape(ref.get("reason", ""))
            cells = (f"no: {why} (the arm's chain)", "", refused, "-", "-")
        body.append(f"<tr><td>{escape(r.hole_id)}</td>"
                    + "".join(f"<td>{c}</td>" for c in cells) + "</tr>")  # fmt: skip
    return f'<table id="referencing">{head}{"".join(body)}</table>'


def referencing_section(results: list[HoleResult], doc: dict[str, Any] | None) -> str:
    """The section's HTML; empty when the run was not referenced."""
    if doc is None or not any("referencing" in r.extra for r in results):
        return ""
    used = {m for r in results for m in r.extra.get("referencing", {}).get("markers", [])}
    return "\n".join([
        "<h2>Referencing: the surveyed markers</h2>",
        "<p class='note'>Each stop is located against the surveyed markers it sees (stereo "
        "resection) and its hole carried into the part by that pose; a stop with fewer than four "
        "usable markers falls back to the arm's kinematic chain with its larger budget.</p>",
        _figures(doc), _network_plot(doc, used), _stops(results),
    ])  # fmt: skip
