"""``report.html`` read back with :mod:`html.parser`: one row per planned hole with U and the
decision, the counts of the summary, and nothing fetched from the network."""

from __future__ import annotations

import dataclasses
from html.parser import HTMLParser
from pathlib import Path

from cell_fixtures import SmallCell

from cell.records.hole_result import HoleResult
from cell.review.report import write_report
from cell.run.setup import start_run


class _Rows(HTMLParser):
    """Cells of every ``tr.hole`` of ``table#holes``, with the row's data attributes."""

    def __init__(self) -> None:
        super().__init__()
        self.rows: list[dict] = []
        self.counts: dict[str, str] = {}
        self.external: list[str] = []
        self._in_table = False
        self._cell: list[str] | None = None
        self._count: str | None = None

    def handle_starttag(self, tag: str, attrs: list) -> None:
        a = dict(attrs)
        for key in ("src", "href"):
            if a.get(key, "").startswith(("http", "//")):
                self.external.append(a[key])
        if tag == "script":
            self.external.append("script")
        if tag == "table" and a.get("id") == "holes":
            self._in_table = True
        elif tag == "tr" and self._in_table and a.get("class") == "hole":
            self.rows.append({"id": a["data-hole"], "decision": a["data-decision"], "cells": []})
        elif tag == "td" and self._in_table and self.rows:
            self._cell = []
        elif tag == "span" and a.get("id", "").startswith("count-"):
            self._count = a["id"][6:]

    def handle_endtag(self, tag: str) -> None:
        if tag == "table":
            self._in_table = False
        elif tag == "td" and self._cell is not None:
            self.rows[-1]["cells"].append("".join(self._cell).strip())
            self._cell = None
        elif tag == "span":
            self._count = None

    def handle_data(self, data: str) -> None:
        if self._cell is not None:
            self._cell.append(data)
        if self._count is not None and data.strip().isdigit():
            self.counts[self._count] = data.strip()


def _result(stop, hole_id: str, decision: str, dev_m: float) -> HoleResult:
    budget = {"k": 2.0, "u_position_m": 1e-5, "u_diameter_m": 1e-6, "U_position_m": 2e-5,
              "U_diameter_m": 2e-6, "notes": [],
              "components": [{"name": "robot_repeatability", "u_position_m": 1e-5,
                              "u_diameter_m": 0.0, "note": "RP"}]}  # fmt: skip
    return HoleResult(hole_id=hole_id, stop_index=stop, status="ok", nominal_part_m=(0.1, 0, 0),
                      nominal_diameter_m=0.01, tolerance_m=5e-5,
                      center_part_m=(0.1 + dev_m, 0, 0), normal_part=(0.0, 0.0, 1.0),
                      diameter_m=0.010001, position_deviation_m=dev_m, axial_deviation_m=0.0,
                      diameter_deviation_m=1e-6, temperatures_c=(21.0, 22.0), sim_time_s=stop,
                      passed=dev_m <= 5e-5, U_position_m=2e-5, U_diameter_m=2e-6,
                      decision=decision, decision_rule="iso14253", budget=budget,
                      extra={"center_part_uncompensated_m": [0.1, 0.0, 0.0]})  # fmt: skip


def test_report_html_has_a_row_per_hole_with_U_and_decision(small_cell: SmallCell,
                                                            tmp_path: Path) -> None:  # fmt: skip
    files = start_run(tmp_path, small_cell.cell, small_cell.tour, "tour.json", "/dev/null")
    stops = small_cell.tour.stops
    files.store.record_hole(_result(0, stops[0].hole_id, "conforming", 10e-6))
    files.store.record_hole(_result(1, stops[1].hole_id, "inconclusive", 40e-6))
    files.store.close()
    summ = write_report(tmp_path, operator="A. Inspector")
    text = (tmp_path / "report.html").read_text()
    parser = _Rows()
    parser.feed(text)
    assert parser.external == []
    assert [r["id"] for r in parser.rows] == [s.hole_id for s in stops]
    first, second, third = parser.rows
    assert first["decision"] == "conforming" and "conformance proven" in first["cells"]
    assert "20.0" in first["cells"]  # U of the position, um
    assert second["decision"] == "inconclusive" and "inconclusive" in second["cells"]
    assert third["decision"] == "" and "not reached" in third["cells"]
    assert parser.counts["conformance-proven"] == "1" == str(summ["holes_conforming"])
    assert parser.counts["inconclusive"] == "1" and parser.counts["nonconformance-proven"] == "0"
    assert "A. Inspector" in text and "<svg" in text


def test_a_store_without_budgets_still_reports(small_cell: SmallCell, tmp_path: Path) -> None:
    files = start_run(tmp_path, small_cell.cell, small_cell.tour, "tour.json", "/dev/null")
    old = dataclasses.replace(_result(0, small_cell.tour.stops[0].hole_id, "", 1e-5),
                              budget=None, U_position_m=None, U_diameter_m=None, decision=None,
                              decision_rule=None, axial_deviation_m=None)  # fmt: skip
    files.store.record_hole(old)
    files.store.close()
    write_report(tmp_path)
    assert "no budget stored" in (tmp_path / "report.html").read_text()
