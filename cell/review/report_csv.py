"""``report.csv``: one row per characteristic of a run, as report.html's characteristics table.

A hole with a position and a size tolerance gives two rows (``kind`` ``position`` and
``diameter``), a hole without any tolerance one row (``kind`` ``none``, no decision); a planned
hole the run did not reach keeps its characteristics' rows, ``not evaluated``; a run whose
drawing could not be evaluated gives each hole's own position row against its old single
``tolerance`` t (a zone of ⌀2t). Columns:

- ``hole_id, characteristic, kind, stop, status, frame, datums, material_condition``: the
  characteristic's id (``SHL1.position``), the frame its value is in (a DRF id, or
  ``fixture``: the cell file's part frame), its datums (``A|B|C``) and material condition;
- ``nominal_x_m .. measured_z_m``: the hole's centre in the part frame; ``nominal_diameter_m``,
  ``diameter_m``: its size;
- ``value_m``: a position's ISO 1101 value (the diameter ⌀ of the zone about the nominal axis
  holding the centre: 2 × its in-plane distance from the nominal), a size's measured diameter;
  ``deviation_m``: a size's measured minus nominal diameter (a position has no sign);
- ``tolerance_m``: a position's zone diameter ⌀t, a size's tolerance (upper minus lower
  deviation, ISO 286); ``lower_limit_m``, ``upper_limit_m``: the limits on ``value_m`` (a
  position: none below, zone plus bonus above; a size: nominal plus each deviation);
  ``bonus_m``: the bonus tolerance at MMC or LMC;
- ``U_m``: the value's expanded uncertainty (k = 2); ``decision``: the words of report.html
  (``conformance proven``, ``inconclusive``, ``nonconformance proven``, ``not evaluated``);
  ``pass``: ``True`` only when conformance is proven, ``False`` only when nonconformance is
  proven, empty otherwise; ``decision_rule``; ``reason``;
- ``axial_deviation_m``, ``thermal_model_id`` and ``u_<component>_m``: the hole's budget
  components (standard uncertainties, k = 1) of the row's value (a position's as ⌀).

Every length is in metres at a fixed resolution of 0.01 µm (:data:`CSV_DECIMALS` decimals).
"""

from __future__ import annotations

import csv
from pathlib import Path
from typing import Any

from cell.gdt.decide import CONFORMANCE, INDETERMINATE, NONCONFORMANCE, NOT_EVALUATED
from cell.review.gdt_html import LABEL
from cell.uncertainty.budget import COMPONENTS
from cell.uncertainty.decision import CONFORMING, INCONCLUSIVE, NONCONFORMING

#: decimals of every length (m): a resolution of 1e-8 m, 0.01 µm
CSV_DECIMALS = 8
HOLE_COLUMNS = (
    "stop", "status", "nominal_x_m", "nominal_y_m", "nominal_z_m",
    "measured_x_m", "measured_y_m", "measured_z_m", "nominal_diameter_m", "diameter_m",
)  # fmt: skip
CSV_COLUMNS = (
    "hole_id", "characteristic", "kind", "stop", "status", "frame", "datums",
    "material_condition", *HOLE_COLUMNS[2:], "value_m", "deviation_m", "tolerance_m",
    "lower_limit_m", "upper_limit_m", "bonus_m", "U_m", "decision", "pass", "decision_rule",
    "reason", "axial_deviation_m", "thermal_model_id", "referenced", "reference_markers",
    *(f"u_{c}_m" for c in COMPONENTS),
)  # fmt: skip
#: text columns (every other column but the ids and counts is a length in m)
_TEXT = {"hole_id", "characteristic", "kind", "status", "frame", "datums", "material_condition",
         "decision", "pass", "decision_rule", "reason", "stop", "thermal_model_id",
         "referenced", "reference_markers"}  # fmt: skip


def _position(c: dict[str, Any], row: dict[str, Any] | None) -> dict[str, Any]:
    return {
        "frame": c["drf"],
        "datums": "|".join(c["datums"]),
        "material_condition": c["material_condition"],
        "value_m": c["value_m"],
        "tolerance_m": c["zone_diameter_m"],
        "upper_limit_m": c["zone_diameter_m"] + (c.get("bonus_m") or 0.0),
        "bonus_m": c.get("bonus_m"),
        "axial_deviation_m": c.get("axial_deviation_m"),
        **_components(row, "position", 2.0),
    }


def _size(c: dict[str, Any], row: dict[str, Any] | None) -> dict[str, Any]:
    return {
        "value_m": c["value_m"],
        "deviation_m": c["deviation_m"],
        "tolerance_m": c["upper_m"] - c["lower_m"],
        "lower_limit_m": c["nominal_m"] + c["lower_m"],
        "upper_limit_m": c["nominal_m"] + c["upper_m"],
        **_components(row, "diameter", 1.0),
    }


def _components(row: dict[str, Any] | None, quantity: str, scale: float) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for c in COMPONENTS:
        v = None if row is None else row.get(f"u_{c}_{quantity}_m")
        out[f"u_{c}_m"] = None if v is None else scale * v
    return out


def _decision(dec: str | None) -> dict[str, Any]:
    return {
        "decision": LABEL.get(dec, "") if dec else "",
        "pass": {CONFORMANCE: True, NONCONFORMANCE: False}.get(dec or ""),
    }


def csv_rows(rows: list[dict[str, Any]], characteristics: list[dict[str, Any]],
             rule: str | None) -> list[dict[str, Any]]:  # fmt: skip
    """The report.csv rows (module doc) of the hole ``rows`` of report.json and its
    ``characteristics``."""
    by_hole = {r["hole_id"]: r for r in rows}
    out, seen = [], set()
    for c in characteristics:
        row = by_hole.get(c["hole_id"])
        seen.add(c["hole_id"])
        spec = _position(c, row) if c["kind"] == "position" else _size(c, row)
        reason = "; ".join(filter(None, [c.get("reason"), (row or {}).get("reason")]))
        out.append({**_hole(row), "hole_id": c["hole_id"], "characteristic": c["id"],
                    "kind": c["kind"], **spec, "U_m": c["U_m"], **_decision(c["decision"]),
                    "decision_rule": rule if c["decision"] != NOT_EVALUATED else "",
                    "reason": reason})  # fmt: skip
    for row in rows:  # holes without a characteristic: their run's own verdict, if any
        if row["hole_id"] not in seen:
            out.append({**_hole(row), **_run_verdict(row, rule)})
    return out


def _run_verdict(row: dict[str, Any], rule: str | None) -> dict[str, Any]:
    """A hole row without characteristics (no drawing evaluated): the run's position against
    its old single ``tolerance`` t (a zone of ⌀2t, docs/gdt.md), or ``kind`` ``none``."""
    base = {"hole_id": row["hole_id"], "frame": row.get("position_frame"),
            "value_m": row.get("position_m"), "U_m": row.get("U_position_m"),
            "axial_deviation_m": row.get("axial_deviation_m")}  # fmt: skip
    t = row.get("tolerance_m")
    if t is None:
        why = "; ".join(filter(None, ["no tolerance", row["reason"]]))
        return {**base, "kind": "none", "reason": why}
    dec = {CONFORMING: CONFORMANCE, NONCONFORMING: NONCONFORMANCE,
           INCONCLUSIVE: INDETERMINATE}.get(row.get("decision") or "")  # fmt: skip
    return {**base, "characteristic": f"{row['hole_id']}.position", "kind": "position",
            "tolerance_m": 2.0 * t, "upper_limit_m": 2.0 * t, **_decision(dec),
            "decision_rule": rule if dec else "", "reason": row["reason"],
            **_components(row, "position", 2.0)}  # fmt: skip


def _hole(row: dict[str, Any] | None) -> dict[str, Any]:
    if row is None:
        return {"status": "not reached"}
    out = {k: row[k] for k in HOLE_COLUMNS}
    out["thermal_model_id"] = row.get("thermal_model_id")
    out["referenced"] = row.get("referenced")
    out["reference_markers"] = row.get("reference_markers")
    return out


def _cell(key: str, v: Any) -> str:
    if v is None:
        return ""
    if key in _TEXT or isinstance(v, (bool, str)):
        return str(v)
    return f"{float(v):.{CSV_DECIMALS}f}"


def write_csv(path: Path, rows: list[dict[str, Any]]) -> None:
    """Write ``rows`` (of :func:`csv_rows`) as ``path``."""
    with path.open("w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=CSV_COLUMNS)
        w.writeheader()
        for row in rows:
            w.writerow({k: _cell(k, row.get(k)) for k in CSV_COLUMNS})
