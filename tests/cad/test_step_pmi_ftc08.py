"""AP242 datums and position tolerances on NIST's FTC-08 test case (public domain,
tests/data/nist/NOTICE.md), checked against a second reading of the file's text
(tests/cad/p21_text.py) and the NIST test case definitions (NIST-FTC-PMI-Definitions.xlsx:
ATC 90 ``⌀.020 (M) (F) |A|B``, ATC 99 the composite ``⌀.050 (M) |D|B|C`` over ``⌀.020 (M)
|D|B|C``)."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml
from p21_text import P21, on_axis

from cell.cad.part import import_step
from cell.config import builtin_cell_path, load_cell
from cell.config.datums import without_drawing
from cell.config.step_part import drawing

FTC08 = Path(__file__).parents[1] / "data" / "nist" / "nist_ftc_08_asme1_ap242-e1.stp"


@pytest.fixture(scope="module")
def ftc08():
    return import_step(FTC08, mesh=False)


@pytest.fixture(scope="module")
def text():
    return P21(FTC08)


def test_ftc08_frame_d_b_c(ftc08, text) -> None:
    datums, _, left = drawing(ftc08.pmi.datums, ftc08.pmi.tolerances)
    assert [d["label"] for d in datums] == ["D", "B", "C"]
    by_id = {h.id: h for h in ftc08.scan.holes}
    for d in datums[1:]:
        hole = by_id[d["hole"]]
        assert all(on_axis(hole.entry_m, text.cylinder(f)) for f in text.datum_faces(d["label"]))
    # D is the face the 16 small holes open into
    assert len(datums[0]["plane"]["holes"]) == 16
    # the other datums (E, F, G, H, J, K, L) are listed, not dropped
    assert sum("not in the frame kept (D|B|C" in line for line in left) == 7
    assert any("datum A: a plane with 0 hole entries" in line for line in ftc08.pmi.unmodelled)


def test_ftc08_positions_as_the_file_states_them(ftc08, text) -> None:
    """Every kept position tolerance is one of the file's, on a hole on the axis of one of its
    faces; every position of the file on holes is either kept there or listed."""
    _, tolerances, left = drawing(ftc08.pmi.datums, ftc08.pmi.tolerances)
    by_id = {h.id: h for h in ftc08.scan.holes}
    stated = text.positions()
    kept = {hid: t["position"] for hid, t in tolerances.items() if "position" in t}
    assert len(kept) == 16
    for hid, pos in kept.items():
        match = [
            s
            for s in stated
            if s["name"] == pos["pmi_id"]
            and abs(s["zone_mm"] * 1e-3 - pos["zone_diameter_m"]) < 1e-12
            and s["datums"] == pos["datums"]
            and ("MAXIMUM_MATERIAL_REQUIREMENT" in s["modifiers"])
            == (pos["material_condition"] == "MMC")
            and any(on_axis(by_id[hid].entry_m, text.cylinder(f)) for f in s["faces"])
        ]
        assert match, (hid, pos)
    # ATC 99: the composite's upper segment (1.27 mm = .050 in) kept, its lower one listed
    assert {round(p["zone_diameter_m"] * 1e3, 6) for p in kept.values()} == {1.016, 1.27, 0.762}
    listed = "\n".join(ftc08.pmi.unmodelled + left)
    assert listed.count("Position 0.508 mm |D|B|C on H") == 14
    assert "a second position tolerance" in listed
    # ATC 90: ⌀.020 (M) in the free state |A|B, and ⌀.023 (M) (F) |A|B|C: listed
    assert (
        "Feature Control Frame (9): Position 0.508 mm |A|B on H02 (zone modifiers Free_State"
        in listed
    )
    assert (
        "Feature Control Frame (7): Position 0.5842 mm |A|B|C on H01, H19 (zone modifiers" in listed
    )


def test_ftc08_size_limits_kept_as_drawn(ftc08) -> None:
    """The 4 holes drawn ⌀6.0452 +0.127/-0.0254 mm (.238 +.005/-.001 in) are modelled at
    ⌀6.0325: the drawing's limits 6.0198..6.1722 mm are kept about the model's diameter."""
    by_id = {h.id: h for h in ftc08.scan.holes}
    for hid in ("H01", "H02", "H19", "H20"):
        size = ftc08.pmi.tolerances[hid]["size"]
        d = by_id[hid].diameter_m
        assert d == pytest.approx(6.0325e-3, abs=1e-9)
        assert d + size["upper_m"] == pytest.approx(6.1722e-3, abs=1e-9)
        assert d + size["lower_m"] == pytest.approx(6.0198e-3, abs=1e-9)
    assert sum("kept about it" in n for n in ftc08.pmi.notes) == 4


def test_ftc08_part_step_gives_a_valid_cell(tmp_path: Path) -> None:
    """``part.step`` with the PMI: the cell file takes the frame D|B|C and the 16 positions at
    MMC or RFS, and passes every datum and tolerance check of the cell file."""
    data = without_drawing(yaml.safe_load(builtin_cell_path().read_text()))
    data["part"]["holes"] = []
    (tmp_path / "ftc08.step").write_bytes(FTC08.read_bytes())
    data["part"]["step"] = {"path": "ftc08.step", "mesh": False}
    cell_path = tmp_path / "cell.yaml"
    cell_path.write_text(yaml.safe_dump(data))
    cfg = load_cell(cell_path)
    assert [d.label for d in cfg.part.datums] == ["D", "B", "C"]
    positions = [
        h.tolerances.position for h in cfg.part.holes if h.tolerances and h.tolerances.position
    ]
    assert len(positions) == 16
    assert {p.material_condition for p in positions} == {"MMC", "RFS"}
    assert all(p.pmi_id and p.pmi_id.startswith("Feature Control Frame") for p in positions)
