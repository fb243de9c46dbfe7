"""report.html of a stored run of the built-in frame (issue 26, finding 10): each chart draws
its characteristics' limits and colours each mark by that characteristic's decision, diameters
are signed against both limits, the map's labels do not overlap, the holes table's tolerance
column is filled, units are written µm, °C and ±, and the deviation triple's axes are named."""

from __future__ import annotations

import itertools
import json
import re
from dataclasses import replace

import pytest
from gdt_fixtures import placement, results, truth

from cell.config import builtin_cell_path, load_builtin_cell
from cell.review.report import write_report
from cell.review.store import Store
from cell.review.svg import text_box
from cell.review.tolerance_charts import COLOR

SMALL = "SPL1"  # made 30 um too small for its H8 hole: the size fails, the position does not


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory) -> tuple[dict, str]:
    folder = tmp_path_factory.mktemp("charts")
    cell = load_builtin_cell()
    cen, dia = truth(cell, 5)
    rs = results(cell, cen, dia, placement(), 5)
    rs = [replace(r, diameter_m=r.nominal_diameter_m - 30e-6) if r.hole_id == SMALL else r
          for r in rs]  # fmt: skip
    holes = [(r.hole_id, r.stop_index, {}) for r in rs]
    with Store.create(folder, cell_name=cell.name, cell_sha256="x",
                      cell_text=builtin_cell_path().read_text(),
                      cell_path=str(builtin_cell_path()), tour_text="{}", reference_text="",
                      robot_model="m", port="p", holes=holes) as store:  # fmt: skip
        for r in rs:
            store.record_hole(r)
        store.set_state("done", finished=True)
    write_report(folder)
    return json.loads((folder / "report.json").read_text()), (folder / "report.html").read_text()


def _svg(html: str, label: str) -> str:
    return re.search(rf'<svg [^>]*aria-label="{re.escape(label)}.*?</svg>', html, re.S).group(0)


def _attrs(tag: str) -> dict[str, str]:
    return dict(re.findall(r'([\w-]+)="([^"]*)"', tag))


def test_charts_draw_the_limits_and_colour_by_the_characteristics_decision(run) -> None:
    doc, html = run
    chars = {c["id"]: c for c in doc["characteristics"]}
    hole = {h["hole_id"]: h for h in doc["holes"]}
    assert chars[f"{SMALL}.diameter"]["decision"] == "nonconformance"
    assert chars[f"{SMALL}.position"]["decision"] == "conformance"
    assert hole[SMALL]["decision"] == "nonconforming"  # the hole's: not its position's
    for label, kind, n_limits in (("position", "position", 1), ("diameter", "diameter", 2)):
        svg = _svg(html, label)
        marks = [_attrs(t) for t in re.findall(r"<(?:rect|circle) class=\"mark\"[^>]*>", svg)]
        ids = [c for c in chars if chars[c]["kind"] == kind and chars[c]["value_m"] is not None]
        assert sorted(m["data-char"] for m in marks) == sorted(ids)
        for m in marks:
            assert m["fill"] == COLOR[chars[m["data-char"]]["decision"]], m
        limits = [_attrs(t)["data-char"] for t in re.findall(r'<line class="limit"[^>]*>', svg)]
        assert sorted(limits) == sorted(i for i in chars if chars[i]["kind"] == kind
                                        for _ in range(n_limits))  # fmt: skip
    diameter = _svg(html, "diameter")
    zero = float(_attrs(re.search(r'<line class="zero"[^>]*>', diameter).group(0))["x1"])
    small = next(_attrs(t) for t in re.findall(r"<circle class=\"mark\"[^>]*>", diameter)
                 if f'data-char="{SMALL}.diameter"' in t)  # fmt: skip
    assert float(small["cx"]) < zero - 5  # signed: below nominal, left of the zero line


def test_the_maps_labels_do_not_overlap(run) -> None:
    _, html = run
    svg = _svg(html, "deviation vectors in the datum reference frame")
    names = {c["hole_id"] for c in run[0]["characteristics"]}
    boxes = [text_box(float(x), float(y), s, int(size)) for x, y, size, s in re.findall(
        r'<text x="([\d.]+)" y="([\d.]+)" font-size="(\d+)"[^>]*>([^<]*)</text>', svg)
        if s in names]  # fmt: skip
    assert len(boxes) > 30
    for a, b in itertools.combinations(boxes, 2):
        assert not (a[0] < b[2] and b[0] < a[2] and a[1] < b[3] and b[1] < a[3]), (a, b)


def test_tables_tolerance_units_and_the_deviation_axes(run) -> None:
    _, html = run
    rows = re.findall(r'<tr class="hole" data-hole="([^"]+)".*?</tr>', html, re.S)
    tol = re.findall(r'<tr class="hole"[^>]*>(?:<td[^>]*>[^<]*</td>){10}<td class=\'l\'>([^<]*)',
                     html)  # fmt: skip
    assert len(tol) == len(rows) == 41 and all(tol), tol
    assert "&#8960;0.500 mm (MMC) to A | B | C" in html
    text = re.sub(r"<[^>]+>", " ", html)
    assert not re.search(r"\bum\b|degC|\+-", text), re.search(r".{30}(\bum\b|degC|\+-).{30}", text)
    assert "µm" in text and "°C" in text and "±" in text
    assert "deviation x / y / z in the DRF (µm)" in html
