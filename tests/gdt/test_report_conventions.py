"""One position convention (ISO 1101: the zone's diameter ⌀, 2 × the in-plane distance) in the
live line, the summary, report.json, report.csv and report.html; report.csv one row per
characteristic with report.html's decision words, its tolerance and a fixed resolution
(issue 26, findings 8 and 9). A stored run of the built-in frame (its drawing: A | B | C)."""

from __future__ import annotations

import csv
import io
import re
from dataclasses import replace
from pathlib import Path

import pytest
from test_gdt_report import _run

from cell.commands.run_progress import RunBars
from cell.records.hole_result import HoleResult
from cell.review.gdt_html import LABEL
from cell.review.report import format_summary
from cell.review.report_csv import CSV_DECIMALS


@pytest.fixture(scope="module")
def report(tmp_path_factory: pytest.TempPathFactory) -> tuple[dict, Path]:
    folder = tmp_path_factory.mktemp("report")
    doc, _ = _run(folder)
    return doc, folder


def test_the_summary_json_and_html_give_the_position_as_a_diameter(report) -> None:
    doc, folder = report
    positions = [c for c in doc["characteristics"] if c["kind"] == "position"]
    worst = max(positions, key=lambda c: c["value_m"])
    s = doc["summary"]
    assert s["worst_position_m"] == pytest.approx(worst["value_m"])  # not half of it
    assert s["worst_hole"] == worst["hole_id"] and s["worst_position_frame"] == "DRF1"
    assert f"worst position  ⌀{worst['value_m'] * 1e3:.4f} mm" in format_summary(s)
    html = (folder / "report.html").read_text()
    row = re.search(rf'data-hole="{worst["hole_id"]}".*?</tr>', html).group(0)
    cells = re.findall(r"<td[^>]*>([^<]*)</td>", row)
    assert cells[4] == f"{worst['value_m'] * 1e6:.1f}"  # the holes table's position ⌀ (um)
    assert cells[5] == f"{worst['U_m'] * 1e6:.1f}"
    assert "position &#8960; (µm)" in html


def test_the_live_line_gives_the_diameter_and_its_frame() -> None:
    r = HoleResult("H1", 0, "ok", (0.0, 0.0, 0.0), 0.01, 5e-5, center_part_m=(0.0, 0.0, 0.0),
                   diameter_m=0.01, position_deviation_m=0.6e-3, diameter_deviation_m=0.0,
                   U_position_m=10e-6, decision="inconclusive")  # fmt: skip
    out = io.StringIO()
    RunBars(1, stream=out)("hole", {"result": replace(r)})
    assert "position ⌀1.2000 mm (fixture frame)" in out.getvalue()
    assert "U ⌀0.0200 mm" in out.getvalue()


def test_report_csv_has_a_row_per_characteristic_with_the_htmls_words(report) -> None:
    doc, folder = report
    text = (folder / "report.csv").read_text()
    rows = list(csv.DictReader(io.StringIO(text)))
    chars = doc["characteristics"]
    assert [r["characteristic"] for r in rows] == [c["id"] for c in chars]
    assert {r["kind"] for r in rows} == {"position", "diameter"}
    for r, c in zip(rows, chars, strict=True):
        assert r["decision"] == LABEL[c["decision"]]
        assert r["pass"] == {"conformance": "True", "nonconformance": "False"}.get(
            c["decision"], ""
        )
        assert r["tolerance_m"] != ""
        if c["kind"] == "position":
            assert r["frame"] == "DRF1" and r["datums"] == "|".join(c["datums"])
            assert float(r["tolerance_m"]) == pytest.approx(c["zone_diameter_m"], abs=1e-8)
            assert float(r["value_m"]) == pytest.approx(c["value_m"], abs=1e-8)
        else:
            assert float(r["tolerance_m"]) == pytest.approx(c["upper_m"] - c["lower_m"], abs=1e-8)
    assert not any(r["pass"] == "True" and r["decision"] != "conformance proven" for r in rows)
    # every length at the stated resolution: no 0.019999999999999997
    numbers = [v for r in rows for k, v in r.items() if k.endswith("_m") and v]
    assert numbers and all(re.fullmatch(rf"-?\d+\.\d{{{CSV_DECIMALS}}}", v) for v in numbers)
