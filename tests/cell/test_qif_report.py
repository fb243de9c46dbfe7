"""``report.qif``: every file we write validates against the vendored QIF 3.0 schemas, a
published community sample validates through the same validator, and the values read back
from the QIF file equal report.json's."""

from __future__ import annotations

import json
import time
from pathlib import Path

import numpy as np
import pytest
from cell_fixtures import SmallCell
from lxml import etree
from qif_reports import NOMINALS, gdt_report
from scipy.spatial.transform import Rotation
from test_cell_report_html import _result

from cell.review.qif import QifError, build_qif, inspection_status, validate_file, write_qif
from cell.review.qif.read import read_qif
from cell.review.qif.validator import SCHEMA_DIR, qif_schema
from cell.review.report import write_report
from cell.run.setup import start_run

STATUS = {
    "conformance": "PASS",
    "nonconformance": "FAIL",
    "inconclusive": "INDETERMINATE",
    "not_evaluated": "NOT_ANALYZED",
}


def test_a_published_qif_sample_validates_offline() -> None:
    qif_schema()
    t = time.perf_counter()
    tree = validate_file(SCHEMA_DIR / "samples" / "testPython30.qif")
    assert time.perf_counter() - t < 2.0
    root = tree.getroot()
    assert root.get("versionQIF") == "3.0.0"
    assert root.find(".//{*}InspectionStatusEnum").text == "FAIL"


def test_the_validator_refuses_a_broken_document(tmp_path: Path) -> None:
    text = (SCHEMA_DIR / "samples" / "testPython30.qif").read_text()
    bad = tmp_path / "bad.qif"
    bad.write_text(text.replace("<InspectionStatusEnum>FAIL", "<InspectionStatusEnum>MAYBE", 1))
    with pytest.raises(QifError, match=r"bad\.qif: line \d+: .*InspectionStatusEnum"):
        validate_file(bad)
    bad.write_text("<QIFDocument")
    with pytest.raises(QifError, match="not XML"):
        validate_file(bad)


def _T(pose: dict) -> np.ndarray:
    T = np.eye(4)
    T[:3, :3] = Rotation.from_quat(pose["quat_xyzw"]).as_matrix()
    T[:3, 3] = pose["xyz"]
    return T


def test_a_gdt_report_round_trips_through_qif(tmp_path: Path) -> None:
    report = gdt_report(np.random.default_rng(3))
    path = write_qif(report, tmp_path / "report.qif", NOMINALS)
    got = read_qif(path)
    chars = {c["id"]: c for c in report["characteristics"]}
    assert [c.name for c in got.characteristics] == list(chars)
    for c in got.characteristics:
        want = chars[c.name]
        assert c.kind == want["kind"] and c.status == STATUS[want["decision"]]
        assert c.value_m == want["value_m"] and c.U_m == want["U_m"]
        if want["U_m"] is not None:
            assert c.combined_uncertainty_m == pytest.approx(want["U_m"] / 2, rel=1e-15)
        if c.kind == "diameter":
            assert (c.nominal_m, c.lower_m, c.upper_m) == (
                want["nominal_m"],
                want["lower_m"],
                want["upper_m"],
            )
        else:
            assert c.zone_m == want["zone_diameter_m"]
            assert c.material_condition == want["material_condition"]
            if want["decision"] != "not_evaluated":
                assert c.bonus_m == (
                    want["bonus_m"] if want["material_condition"] != "RFS" else None
                )
                assert c.drf_transform == "DRF1 T_part_drf"
        assert c.reason == want["reason"]
    assert got.inspection_status == inspection_status(report["characteristics"]) == "UNKNOWN"
    drf = report["datum_reference_frames"][0]
    np.testing.assert_allclose(got.transforms["DRF1 T_part_drf"], _T(drf["T_part_drf"]), atol=1e-15)
    np.testing.assert_allclose(
        got.transforms["placement T_fixture_part"],
        _T(report["placement"]["T_fixture_part"]),
        atol=1e-15,
    )
    for h in report["holes"]:
        if h["measured_x_m"] is None:
            assert h["hole_id"] not in got.features
            continue
        centre, dia, _axis = got.features[h["hole_id"]]
        assert list(centre) == [h["measured_x_m"], h["measured_y_m"], h["measured_z_m"]]
        assert dia == h["diameter_m"]


def test_qif_sections_name_datums_frames_and_features(tmp_path: Path) -> None:
    root = build_qif(gdt_report(np.random.default_rng(1)), NOMINALS)
    q = "{http://qifstandards.org/xsd/qif3}"
    labels = [e.text for e in root.iter(q + "DatumLabel")]
    assert labels == ["A", "B", "C"]
    prec = [e.text for e in root.iter(q + "PrecedenceEnum")]
    assert prec == ["PRIMARY", "SECONDARY", "TERTIARY"]
    assert len(root.findall(f"{q}Features/{q}FeatureNominals/{q}CircleFeatureNominal")) == 7
    plane = root.find(f"{q}Features/{q}FeatureNominals/{q}PlaneFeatureNominal")
    assert plane.find(q + "Normal").text == "0.0 0.0 1.0"
    pos = root.find(f".//{q}PositionCharacteristicDefinition")
    assert pos.find(q + "MaterialCondition").text == "MAXIMUM"
    assert pos.find(f"{q}ZoneShape/{q}DiametricalZone") is not None
    assert root.find(f"{q}FileUnits/{q}PrimaryUnits/{q}LinearUnit/{q}SIUnitName").text == "meter"


@pytest.mark.parametrize(
    ("decisions", "status"),
    [
        ([], "NOT_CALCULATED"),
        (["conformance"] * 3, "PASS"),
        (["conformance", "inconclusive"], "UNKNOWN"),
        (["conformance", "not_evaluated"], "UNKNOWN"),
        (["inconclusive", "nonconformance", "not_evaluated"], "FAIL"),
    ],
)
def test_inspection_status(decisions: list[str], status: str) -> None:
    assert inspection_status([{"decision": d} for d in decisions]) == status


def test_bad_reports_are_refused_with_the_field_named(tmp_path: Path) -> None:
    report = gdt_report(np.random.default_rng(2))
    report["datums"][1]["holes"] = ["NOPE"]
    with pytest.raises(QifError, match=r"datum B: unknown hole\(s\) \['NOPE'\]"):
        write_qif(report, tmp_path / "r.qif", NOMINALS)
    report = gdt_report(np.random.default_rng(2))
    report["characteristics"][0]["decision"] = "fine"
    with pytest.raises(QifError, match="decision 'fine'"):
        write_qif(report, tmp_path / "r.qif", NOMINALS)
    with pytest.raises(QifError, match="hole 'H1' is not in the run's cell file"):
        write_qif(
            gdt_report(np.random.default_rng(2)),
            tmp_path / "r.qif",
            {k: v for k, v in NOMINALS.items() if k != "H1"},
        )
    assert not (tmp_path / "r.qif").exists()


def test_every_run_writes_a_valid_report_qif_equal_to_report_json(
    small_cell: SmallCell, tmp_path: Path
) -> None:
    files = start_run(tmp_path, small_cell.cell, small_cell.tour, "tour.json", "/dev/null")
    stops = small_cell.tour.stops
    files.store.record_hole(_result(0, stops[0].hole_id, "conforming", 10e-6))
    files.store.record_hole(_result(1, stops[1].hole_id, "inconclusive", 40e-6))
    files.store.close()
    write_report(tmp_path)
    doc = json.loads((tmp_path / "report.json").read_text())
    got = read_qif(tmp_path / "report.qif")
    measured = [h for h in doc["holes"] if h["measured_x_m"] is not None]
    assert sorted(got.features) == sorted(h["hole_id"] for h in measured)
    for h in measured:
        centre, dia, axis = got.features[h["hole_id"]]
        assert list(centre) == [h["measured_x_m"], h["measured_y_m"], h["measured_z_m"]]
        assert dia == h["diameter_m"] and list(axis) == [0.0, 0.0, 1.0]
    want_chars = doc.get("characteristics") or []
    assert len(got.characteristics) == len(want_chars)
    for c, want in zip(got.characteristics, want_chars, strict=True):
        assert (c.name, c.value_m, c.U_m) == (want["id"], want["value_m"], want["U_m"])
    assert got.inspection_status == inspection_status(want_chars)
    tree = etree.parse(str(tmp_path / "report.qif"))
    nominal = tree.getroot().findall(".//{*}CircleFeatureNominal")
    assert len(nominal) == len(small_cell.cell.part.holes) == 3  # the unreached hole too
    assert len(doc["holes"]) == 2


def test_a_best_fit_and_the_fixture_frame_are_no_drf(tmp_path: Path) -> None:
    """A best-fit alignment (``ALIGN``, no datums) and the fixture frame of a cell without
    datums: the positions carry no DRF, the best fit's transform is still in the results."""
    report = gdt_report(np.random.default_rng(5), missing=())
    report["datum_reference_frames"][0].update(id="ALIGN", datums=[])
    report["datums"] = []
    for c in report["characteristics"]:
        if c["kind"] == "position":
            c["drf"], c["datums"] = ("ALIGN", []) if c["hole_id"] == "H1" else ("fixture", [])
    got = read_qif(write_qif(report, tmp_path / "report.qif", NOMINALS))
    assert {c.name for c in got.characteristics} >= {"H1.position", "H2.position"}
    assert all(c.drf_transform is None for c in got.characteristics)
    assert "ALIGN T_part_drf" in got.transforms
    root = etree.parse(str(tmp_path / "report.qif")).getroot()
    assert root.find("{*}DatumReferenceFrames") is None
    assert root.find(".//{*}PositionCharacteristicDefinition/{*}DatumReferenceFrameId") is None
    report["characteristics"][1]["drf"] = "DRF9"
    with pytest.raises(QifError, match=r"H1\.position: unknown DRF 'DRF9'"):
        write_qif(report, tmp_path / "r.qif", NOMINALS)


def test_a_run_without_a_readable_cell_file_names_it() -> None:
    from cell.errors import ConfigError
    from cell.review.qif.run_file import hole_nominals

    with pytest.raises(ConfigError, match=r"^runs/r1 \(cell\): robot: the run's cell file: "):
        hole_nominals({"cell_text": "name: c\n", "cell_path": ""}, "runs/r1 (cell)")
    with pytest.raises(ConfigError, match=r"\(yaml\): the run's cell file: "):
        hole_nominals({"cell_text": "a: [\n", "cell_path": ""}, "runs/r1 (cell)")


def test_the_reader_converts_a_community_sample_from_mm(tmp_path: Path) -> None:
    got = read_qif(SCHEMA_DIR / "samples" / "testPython30.qif")
    by = {c.name: c for c in got.characteristics}
    assert by["DIAM1_B"].value_m == pytest.approx(0.012699)
    assert (by["DIAM1_B"].lsl_m, by["DIAM1_B"].usl_m) == pytest.approx((0.0124, 0.0130))
    assert (by["DIAM2"].lsl_m, by["DIAM2"].usl_m) == pytest.approx((0.0063, 0.0065))  # limits
    assert by["DIAM2"].status == "FAIL" and by["POSN1"].zone_m == pytest.approx(0.0005)
    assert got.features["CIRC1"][1] == pytest.approx(0.0062)
    text = (SCHEMA_DIR / "samples" / "testPython30.qif").read_text()
    other = tmp_path / "feet.qif"
    other.write_text(
        text.replace("<SIUnitName>meter</SIUnitName>", "<SIUnitName>foot</SIUnitName>")
    )
    with pytest.raises(QifError, match=r"feet\.qif: line \d+: .*SIUnitName.*'foot'"):
        read_qif(other)
