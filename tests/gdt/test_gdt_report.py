"""report.json and report.html of a stored run of the built-in frame: the schema's fields, the
per-hole fields taken from the characteristics, and the tables read back from the HTML."""

from __future__ import annotations

import json
from html.parser import HTMLParser
from pathlib import Path

import pytest
from gdt_fixtures import placement, results, truth

from cell.config import builtin_cell_path, load_builtin_cell
from cell.review.report import write_report
from cell.review.store import Store


class _Tables(HTMLParser):
    """Rows of the gdt tables: (table id, row attributes)."""

    def __init__(self) -> None:
        super().__init__()
        self.table, self.rows, self.counts = "", [], ""
        self._in_counts = False

    def handle_starttag(self, tag: str, attrs: list) -> None:
        a = dict(attrs)
        if tag == "table":
            self.table = a.get("id", "")
        if tag == "tr" and a.get("class") in ("drf", "char"):
            self.rows.append((self.table, a))
        if tag == "p" and a.get("id") == "char-counts":
            self._in_counts = True

    def handle_data(self, data: str) -> None:
        if self._in_counts:
            self.counts += data

    def handle_endtag(self, tag: str) -> None:
        if tag == "p":
            self._in_counts = False


def _run(tmp_path: Path, missing: tuple[str, ...] = ()) -> tuple[dict, _Tables]:
    cell = load_builtin_cell()
    cen, dia = truth(cell, 5)
    rs = results(cell, cen, dia, placement(), 5, missing)
    text = builtin_cell_path().read_text()
    holes = [(r.hole_id, r.stop_index, {}) for r in rs]
    with Store.create(tmp_path, cell_name=cell.name, cell_sha256="x", cell_text=text,
                      cell_path=str(builtin_cell_path()), tour_text="{}", reference_text="",
                      robot_model="m", port="p", holes=holes) as store:  # fmt: skip
        for r in rs:
            store.record_hole(r)
        store.set_state("done", finished=True)
    write_report(tmp_path)
    parser = _Tables()
    parser.feed((tmp_path / "report.html").read_text())
    return json.loads((tmp_path / "report.json").read_text()), parser


def test_report_json_and_html_carry_the_characteristics(tmp_path: Path) -> None:
    doc, html = _run(tmp_path)
    assert doc["alignment"] == "DRF1" and doc["datum_reference_frames"][0]["status"] == "evaluated"
    assert doc["placement"]["status"] == "evaluated"
    chars = doc["characteristics"]
    assert len(chars) == 80
    rows = [a for t, a in html.rows if t == "characteristics"]
    assert [a["data-char"] for a in rows] == [c["id"] for c in chars]
    assert [a["data-decision"] for a in rows] == [c["decision"] for c in chars]
    assert [(a["data-drf"], a["data-status"]) for t, a in html.rows if t == "drfs"] == [
        ("DRF1", "evaluated")]  # fmt: skip
    counts = doc["summary"]["characteristics"]
    assert f"{counts['conformance']} conformance proven" in html.counts
    assert counts["conformance"] >= 70 and counts["not_evaluated"] == 0
    by_hole = {h["hole_id"]: h for h in doc["holes"]}
    pos = next(c for c in chars if c["id"] == "SHL1.position")
    assert by_hole["SHL1"]["position_m"] == pytest.approx(pos["value_m"])  # ISO 1101: the ⌀
    assert by_hole["SHL1"]["U_position_m"] == pytest.approx(pos["U_m"])
    assert by_hole["SHL1"]["position_frame"] == "DRF1"
    assert by_hole["SHL1"]["decision"] in ("conforming", "inconclusive")
    assert "<h2>Deviation vectors over the part</h2>" not in (tmp_path / "report.html").read_text()


def test_report_of_a_run_whose_datum_was_not_measured(tmp_path: Path) -> None:
    doc, html = _run(tmp_path, missing=("HT1",))
    assert [(a["data-drf"], a["data-status"]) for t, a in html.rows if t == "drfs"] == [
        ("DRF1", "not_evaluated")]  # fmt: skip
    not_eval = [a for t, a in html.rows if t == "characteristics"
                and a["data-decision"] == "not_evaluated"]  # fmt: skip
    assert len(not_eval) == 40  # 39 positions and the missing hole's size
    assert doc["placement"]["status"] == "not_evaluated"
    not_pos = [c for c in doc["characteristics"] if c["decision"] == "not_evaluated"
               and c["kind"] == "position"]  # fmt: skip
    assert all(len(c["nominal_m"]) == 3 and c["value_m"] is None for c in not_pos)
    row = next(h for h in doc["holes"] if h["hole_id"] == "SHL1")
    assert row["position_m"] is None and row["decision"] is None
    assert "datum C" in row["reason"] and "HT1" in row["reason"]
    assert doc["summary"]["characteristics"]["not_evaluated"] == 40
