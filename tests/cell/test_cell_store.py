"""The results store: one row per hole, duplicates refused, corrupt files refused untouched."""

from __future__ import annotations

import csv
import dataclasses
import json
from pathlib import Path

import pytest
import yaml

from cell.config import builtin_cell_path
from cell.records.hole_result import HoleResult
from cell.review.report import write_report
from cell.review.store import Store, StoreError


def _cell_text() -> str:
    """The built-in cell with its first two holes named H1 and H2 and no datums or tolerances
    (report.qif reads the holes' nominals from the run's cell file)."""
    data = yaml.safe_load(builtin_cell_path().read_text())
    data["part"]["holes"] = data["part"]["holes"][:2]
    for key in ("datums", "alignment"):  # datums name holes this cell no longer has
        data["part"].pop(key, None)
    for hole, name in zip(data["part"]["holes"], ("H1", "H2"), strict=True):
        hole["id"] = name
        hole.pop("tolerances", None)
    return yaml.safe_dump(data, sort_keys=False)


def _store(tmp_path: Path) -> Store:
    holes = [("H1", 0, {"d": 0.01}), ("H2", 1, {"d": 0.01})]
    return Store.create(tmp_path, cell_name="c", cell_sha256="abc", cell_text=_cell_text(),
                        cell_path="", tour_text="{}", reference_text="", robot_model="m",
                        port="/dev/null", holes=holes)  # fmt: skip


def _result(hole: str, stop: int, status: str = "ok") -> HoleResult:
    measured = status != "missing"
    return HoleResult(
        hole_id=hole,
        stop_index=stop,
        status=status,
        nominal_part_m=(0.1, 0.2, 0.3),
        nominal_diameter_m=0.01,
        tolerance_m=5e-5,
        center_part_m=(0.1, 0.2, 0.30001) if measured else None,
        diameter_m=0.010002 if measured else None,
        position_deviation_m=1e-5 if measured else None,
        diameter_deviation_m=2e-6 if measured else None,
        q_rad=(0.0,) * 6,
        temperatures_c=(20.0, 21.0),
        reason="" if measured else "no hole found",
        passed=(status != "fail") if measured else None,
    )


def test_round_trip_and_no_duplicate(tmp_path: Path) -> None:
    with _store(tmp_path) as s:
        s.record_hole(_result("H1", 0))
        with pytest.raises(StoreError, match="already stored"):
            s.record_hole(_result("H1", 0))
        with pytest.raises(StoreError, match="not planned"):
            s.record_hole(_result("H9", 5))
    with Store.open(tmp_path) as s:
        assert s.stored_ids() == {"H1"}
        assert s.results() == [_result("H1", 0)]
        assert s.run_info()["cell_name"] == "c"
    assert _journal(tmp_path) == "wal"


def _journal(tmp_path: Path) -> str:
    import sqlite3

    con = sqlite3.connect(tmp_path / "results.sqlite")
    try:
        return con.execute("PRAGMA journal_mode").fetchone()[0]
    finally:
        con.close()


def test_create_refuses_existing_run(tmp_path: Path) -> None:
    _store(tmp_path).close()
    with pytest.raises(StoreError, match="--resume"):
        _store(tmp_path)


@pytest.mark.parametrize("damage", ["garbage", "truncate"])
def test_corrupt_store_is_refused_and_left_alone(tmp_path: Path, damage: str) -> None:
    with _store(tmp_path) as s:
        s.record_hole(_result("H1", 0))
    path = tmp_path / "results.sqlite"
    data = path.read_bytes()
    bad = b"this is not sqlite" * 100 if damage == "garbage" else data[: len(data) // 3]
    path.write_bytes(bad)
    with pytest.raises(StoreError, match=r"results\.sqlite"):
        Store.open(tmp_path)
    assert path.read_bytes() == bad


def test_missing_store_is_a_clear_error(tmp_path: Path) -> None:
    with pytest.raises(StoreError, match="not a run directory"):
        Store.open(tmp_path)


def test_report_files(tmp_path: Path) -> None:
    with _store(tmp_path) as s:
        s.record_hole(_result("H1", 0))
        s.record_hole(_result("H2", 1, "missing"))
        s.set_state("done", finished=True)
    summ = write_report(tmp_path)
    assert summ["holes_measured"] == 1 and summ["holes_missing"] == 1
    doc = json.loads((tmp_path / "report.json").read_text())
    assert [h["hole_id"] for h in doc["holes"]] == ["H1", "H2"]
    rows = list(csv.DictReader((tmp_path / "report.csv").open()))
    # no drawing: the run's position (⌀, 2 x 10 um) against the old tolerance's zone (⌀2t);
    # no decision was stored, so no pass either
    assert rows[0]["value_m"] == "0.00002000" and rows[0]["tolerance_m"] == "0.00010000"
    assert rows[0]["pass"] == "" and rows[1]["measured_x_m"] == ""
    assert float(rows[0]["measured_z_m"]) == pytest.approx(0.30001)
    assert (tmp_path / "report.qif").is_file()


def test_failed_creation_leaves_no_store(tmp_path: Path) -> None:
    """Two planned holes with one id: refused as a StoreError, and no results.sqlite (nor any
    temporary file) is left to block a new run."""
    with pytest.raises(StoreError, match="nothing was written"):
        Store.create(tmp_path, cell_name="c", cell_sha256="0", cell_text="", cell_path="",
                     tour_text="{}", reference_text="", robot_model="m", port="p",
                     holes=[("H1", 0, {}), ("H1", 1, {})])  # fmt: skip
    assert list(tmp_path.iterdir()) == []
    with _store(tmp_path) as s:
        assert [h for h, _, _ in s.planned()] == ["H1", "H2"]


def test_version_1_store_is_upgraded_without_loss(tmp_path: Path) -> None:
    import sqlite3

    with _store(tmp_path) as s:
        s.record_hole(_result("H1", 0))
    con = sqlite3.connect(tmp_path / "results.sqlite")
    with con:
        con.execute("DROP TABLE reference_observations")
        con.execute("DROP TABLE thermal_models")
        con.execute("UPDATE meta SET value = '1'")
    con.close()
    with Store.open(tmp_path) as s:
        assert [r.hole_id for r in s.results()] == ["H1"]
        s.record_reference(0, 1.0, "R1", [0.0] * 6, [20.0] * 6, [0.0, 0.0, 0.3])
        assert s.record_model("given", "{}") == 1 and len(s.reference_observations()) == 1


def test_version_2_store_is_upgraded_and_keeps_budgets(tmp_path: Path) -> None:
    """A schema-2 store gets the uncertainty table; a hole's budget components are stored in
    it, and an unmeasured attempt's rows go with the attempt."""
    import sqlite3

    with _store(tmp_path) as s:
        s.record_hole(_result("H1", 0))
    con = sqlite3.connect(tmp_path / "results.sqlite")
    with con:
        con.execute("DROP TABLE uncertainty")
        con.execute("UPDATE meta SET value = '2' WHERE key = 'schema_version'")
    con.close()
    budget = {"k": 2.0, "u_position_m": 1e-5, "u_diameter_m": 2e-6, "U_position_m": 2e-5,
              "U_diameter_m": 4e-6, "notes": [],
              "components": [{"name": "circle_fit", "u_position_m": 1e-6, "u_diameter_m": 1e-6,
                              "note": "fit"},
                             {"name": "robot_repeatability", "u_position_m": 9e-6,
                              "u_diameter_m": 0.0, "note": "RP"}]}  # fmt: skip
    with Store.open(tmp_path) as s:
        s.record_hole(dataclasses.replace(_result("H2", 1), budget=budget, U_position_m=2e-5,
                                          decision="conforming"))  # fmt: skip
        rows = s.uncertainty_rows()
        assert [(h, c) for h, c, *_ in rows] == [("H2", "circle_fit"),
                                                 ("H2", "robot_repeatability")]  # fmt: skip
        assert s.results()[1].decision == "conforming" and s.results()[0].decision is None
        s.set_part_state({"temperature_c": 21.0})
        assert s.part_state() == {"temperature_c": 21.0}
    con = sqlite3.connect(tmp_path / "results.sqlite")
    assert con.execute("SELECT value FROM meta WHERE key='schema_version'").fetchone()[0] == "3"
    con.close()
