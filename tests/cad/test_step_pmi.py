"""AP242 semantic PMI (cell/cad/pmi.py) on NIST's CTC-01 test case (public domain,
tests/data/nist/NOTICE.md) and "no semantic PMI" on a generated part."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from cad_parts import write_part
from p21_text import P21, on_axis

from cell.cad.part import import_step
from cell.cli import main
from cell.config.step_part import drawing

NIST = Path(__file__).parents[1] / "data" / "nist" / "nist_ctc_01_asme1_ap242.stp"


@pytest.fixture(scope="module")
def ctc01():
    return import_step(NIST, mesh=False)


def test_ctc01_holes(ctc01) -> None:
    holes = ctc01.scan.holes
    assert len(holes) == 10
    sizes = sorted(round(h.diameter_m * 1e3, 6) for h in holes)
    assert sizes == [20, 20, 25, 25, 25, 25, 35, 35, 35, 35]
    blind = [h for h in holes if not h.through]
    # the two side holes end in a drill point: 45 mm of wall, the cone not counted
    assert [round(h.depth_m * 1e3, 6) for h in blind] == [45, 45]
    assert all(h.countersunk for h in blind)


def _limits_in_text() -> set[tuple[float, float]]:
    """The upper/lower limits of the size dimensions as the STEP text states them (a second
    reading, by regular expression, of what OpenCascade reads)."""
    text = NIST.read_text(encoding="latin-1")
    upper = re.findall(
        r"LENGTH_MEASURE\(([-\d.]+)\),#\d+\)\s*REPRESENTATION_ITEM\('upper limit'", text
    )
    lower = re.findall(
        r"LENGTH_MEASURE\(([-\d.]+)\),#\d+\)\s*REPRESENTATION_ITEM\('lower limit'", text
    )
    return {(float(u), float(lo)) for u, lo in zip(upper, lower, strict=True)}


def test_ctc01_size_tolerances_as_the_file_states_them(ctc01) -> None:
    by_id = {h.id: h for h in ctc01.scan.holes}
    sizes = {hid: t["size"] for hid, t in ctc01.pmi.tolerances.items() if "size" in t}
    assert len(sizes) == 7
    assert all(s["pmi_id"] == "diameter" for s in sizes.values())
    limits = {
        (
            round((by_id[h].diameter_m + s["upper_m"]) * 1e3, 6),
            round((by_id[h].diameter_m + s["lower_m"]) * 1e3, 6),
        )
        for h, s in sizes.items()
    }
    assert _limits_in_text() <= limits  # the 35.2/34.8 range dimensions
    # the plus/minus ones: 35 -0.2/0, 35 +0.2/0, 20 +0.05/-0.1, 20 +0.1/-0.05, 25 +-0.15
    assert {(35.0, 34.8), (35.2, 35.0), (20.05, 19.9), (20.1, 19.95), (25.15, 24.85)} <= limits


def test_ctc01_what_is_not_modelled_is_listed(ctc01) -> None:
    listed = "\n".join(ctc01.pmi.unmodelled)
    for name in ("Flatness.1", "Perpendicularity.1", "Position surfacic profile.2",
                 "Position.1", "Position.2"):  # fmt: skip
        assert name in listed
    # the two position tolerances are on the slots' planar walls, no hole
    assert "Position.1: Position 0.75 mm |A|B|C (on 2 faces, none a hole's wall)" in listed


def test_ctc01_datums_come_through_as_a_frame(ctc01) -> None:
    by_label = {d["label"]: d for d in ctc01.pmi.datums}
    assert by_label["B"] == {"label": "B", "hole": "H01", "pmi_id": "datum B"}
    assert by_label["C"] == {"label": "C", "hole": "H09", "pmi_id": "datum C"}
    # A: the top face, through the entry rims of the 8 holes that open into it
    assert len(by_label["A"]["plane"]["holes"]) == 8
    # B and C: OpenCascade's XCAF attaches them to no face; the entity graph gives them
    assert sum("entity graph" in n for n in ctc01.pmi.notes) == 2
    datums, _, left = drawing(ctc01.pmi.datums, ctc01.pmi.tolerances)
    assert [d["label"] for d in datums] == ["A", "B", "C"] and left == []


def test_ctc01_datum_holes_as_the_file_states_them(ctc01) -> None:
    """The faces of datums B and C read a second time from the STEP text (their cylinders'
    axes and radii): the holes kept lie on those axes, with those diameters."""
    text = P21(NIST)
    by_id = {h.id: h for h in ctc01.scan.holes}
    by_label = {d["label"]: d for d in ctc01.pmi.datums}
    for letter in ("B", "C"):
        faces = text.datum_faces(letter)
        assert len(faces) == 2  # two half cylinders
        hole = by_id[by_label[letter]["hole"]]
        for face in faces:
            axis = text.cylinder(face)
            assert axis is not None and on_axis(hole.entry_m, axis)
            assert abs(2 * axis[2] * 1e-3 - hole.diameter_m) < 1e-9
        others = [h for h in ctc01.scan.holes if h is not hole]
        assert not any(on_axis(h.entry_m, text.cylinder(min(faces))) for h in others)


def test_no_semantic_pmi_is_said(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path, _ = write_part("plate", tmp_path)
    assert not import_step(path, mesh=False).pmi.semantic
    assert main(["import-step", str(path), "-o", str(tmp_path / "h.csv")]) == 0
    assert "no semantic PMI" in capsys.readouterr().out


def test_ctc01_part_yaml_carries_the_tolerances(tmp_path: Path) -> None:
    import yaml

    out = tmp_path / "part.yaml"
    assert main(["import-step", str(NIST), "-o", str(tmp_path / "h.csv"), "--yaml", str(out)]) == 0
    part = yaml.safe_load(out.read_text())["part"]
    toleranced = [h for h in part["holes"] if "tolerances" in h]
    assert len(toleranced) == 7
    assert [(d["label"], d["pmi_id"]) for d in part["datums"]] == [
        ("A", "datum A"),
        ("B", "datum B"),
        ("C", "datum C"),
    ]
    assert {h["tolerances"]["size"]["pmi_id"] for h in toleranced} == {"diameter"}
    from cell.config.schema import Hole

    assert all(Hole.model_validate(h).tolerances is not None for h in toleranced)


def test_a_maximum_tolerance_is_read_from_the_text(tmp_path: Path) -> None:
    """XCAF drops a position's maximum value (``|⌀.045 MAX|``): the entity graph names the
    tolerances that have one (the entity as NIST FTC-07 in AP242 writes GP6)."""
    from cell.cad.pmi_graph import StepGraph

    step = tmp_path / "max.stp"
    step.write_text(
        "ISO-10303-21;\nHEADER;\nENDSEC;\nDATA;\n"
        "#16533= ( GEOMETRIC_TOLERANCE('GP6','',#16532,#15545) "
        "GEOMETRIC_TOLERANCE_WITH_DATUM_REFERENCE((#16290)) "
        "GEOMETRIC_TOLERANCE_WITH_MAXIMUM_TOLERANCE(#16531) "
        "GEOMETRIC_TOLERANCE_WITH_MODIFIERS((.MAXIMUM_MATERIAL_REQUIREMENT.)) "
        "POSITION_TOLERANCE() );\n"
        "#16534= ( GEOMETRIC_TOLERANCE('GP7','',#16532,#15545) "
        "GEOMETRIC_TOLERANCE_WITH_DATUM_REFERENCE((#16290)) POSITION_TOLERANCE() );\n"
        "ENDSEC;\nEND-ISO-10303-21;\n",
        encoding="latin-1",
    )
    assert StepGraph(step).capped == {"GP6"}
