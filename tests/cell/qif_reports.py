"""Synthetic report.json mappings with datums and characteristics (the field set of the
report schema shared with the GD&T evaluation), for the QIF and SPC tests."""

from __future__ import annotations

from typing import Any

import numpy as np

from cell.review.qif.features import HoleNominal

#: (hole id, nominal centre m, axis, nominal diameter m)
HOLES = (
    ("A1", (0.0, 0.0, 0.0), (0.0, 0.0, 1.0), 0.010),
    ("A2", (0.2, 0.0, 0.0), (0.0, 0.0, 1.0), 0.010),
    ("A3", (0.0, 0.15, 0.0), (0.0, 0.0, 1.0), 0.010),
    ("B", (0.05, 0.05, 0.0), (0.0, 0.0, 1.0), 0.020),
    ("C", (0.25, 0.05, 0.0), (0.0, 0.0, 1.0), 0.012),
    ("H1", (0.1, 0.1, 0.0), (0.0, 0.0, 1.0), 0.008),
    ("H2", (0.15, 0.12, 0.01), (0.0, 0.6, 0.8), 0.006),
)
#: the cell file's holes, as the QIF writer takes them
NOMINALS = {h[0]: HoleNominal(h[1], h[2], h[3]) for h in HOLES}


def _hole_row(hid, nominal, diameter, measured, dia, U_pos, U_dia) -> dict[str, Any]:
    row = {
        "hole_id": hid,
        "status": "ok" if measured is not None else "missing",
        "nominal_diameter_m": diameter,
        "diameter_m": dia,
        "U_position_m": U_pos,
        "U_diameter_m": U_dia,
    }
    for i, a in enumerate("xyz"):
        row[f"nominal_{a}_m"] = nominal[i]
        row[f"measured_{a}_m"] = None if measured is None else measured[i]
    return row


def gdt_report(
    rng: np.random.Generator,
    started_at: float = 1.8e9,
    *,
    position_offset_m: float = 0.0,
    position_sigma_m: float = 2e-5,
    diameter_sigma_m: float = 3e-6,
    missing: tuple[str, ...] = ("H2",),
    mmc: bool = True,
) -> dict[str, Any]:
    """A report with datums A (plane over A1-A3), B (hole), C (hole), DRF1 A|B|C, a placement,
    and a position and diameter characteristic per non-datum hole. H1's x deviation in the DRF
    is ``position_offset_m`` + N(0, ``position_sigma_m``), its diameter deviation
    N(10 um, ``diameter_sigma_m``); ``missing`` holes are not measured (not evaluated)."""
    holes, chars = [], []
    for hid, nominal, _axis, diameter in HOLES:
        if hid in missing:
            holes.append(_hole_row(hid, nominal, diameter, None, None, None, None))
            chars += _char_missing(hid, diameter)
            continue
        dev = rng.normal(0.0, 1.5e-5, 3) * (1, 1, 0.3)
        if hid == "H1":
            dev[0] = position_offset_m + rng.normal(0.0, position_sigma_m)
        ddia = 1e-5 + rng.normal(0.0, diameter_sigma_m)
        meas = [float(n + d) for n, d in zip(nominal, dev, strict=True)]
        holes.append(_hole_row(hid, nominal, diameter, meas, diameter + ddia, 3e-5, 4e-6))
        if hid.startswith(("A", "B", "C")):
            continue
        chars += _chars(hid, nominal, meas, diameter, ddia, mmc)
    return {
        "format": "holecell.report",
        "version": 1,
        "summary": {"cell": "synthetic", "cell_sha256": "0" * 64, "started_at": started_at},
        "holes": holes,
        "datums": [
            {
                "label": "A",
                "kind": "plane",
                "holes": ["A1", "A2", "A3"],
                "measured": True,
                "reason": "",
            },
            {"label": "B", "kind": "hole", "holes": ["B"], "measured": True, "reason": ""},
            {"label": "C", "kind": "hole", "holes": ["C"], "measured": True, "reason": ""},
        ],
        "datum_reference_frames": [
            {
                "id": "DRF1",
                "datums": ["A", "B", "C"],
                "T_part_drf": {"xyz": [0.05, 0.05, 1e-5], "quat_xyzw": [0.0, 0.0, 0.0017, 1.0]},
                "U_T_part_drf": {"xyz_m": [1e-5] * 3, "rotation_rad": [1e-5] * 3},
                "residuals_m": {"A": 1e-5, "B": 2e-6, "C": 3e-6},
                "status": "evaluated",
                "reason": "",
            }
        ],
        "placement": {
            "T_fixture_part": {
                "xyz": [0.0015, -0.0002, 0.0],
                "quat_xyzw": [0.0, 0.0, 0.0035, 0.99999],
            },
            "U_xyz_m": [2e-5] * 3,
            "U_rotation_rad": [2e-5] * 3,
        },
        "characteristics": chars,
    }


def _decision(value: float, U: float, lo: float, hi: float) -> str:
    if lo + U <= value <= hi - U:
        return "conformance"
    if value < lo - U or value > hi + U:
        return "nonconformance"
    return "inconclusive"


def _chars(hid, nominal, meas, diameter, ddia, mmc) -> list[dict[str, Any]]:
    dx, dy, dz = (m - n for m, n in zip(meas, nominal, strict=True))
    value = 2.0 * float(np.hypot(dx, dy))
    bonus = max(ddia, 0.0) if mmc else 0.0
    zone = 3e-4
    return [
        {
            "id": f"{hid}.diameter",
            "hole_id": hid,
            "kind": "diameter",
            "nominal_m": diameter,
            "upper_m": 2.2e-5,
            "lower_m": 0.0,
            "actual_m": diameter + ddia,
            "deviation_m": ddia,
            "value_m": diameter + ddia,
            "U_m": 4e-6,
            "decision": _decision(ddia, 4e-6, 0.0, 2.2e-5),
            "reason": "",
        },
        {
            "id": f"{hid}.position",
            "hole_id": hid,
            "kind": "position",
            "drf": "DRF1",
            "datums": ["A", "B", "C"],
            "material_condition": "MMC" if mmc else "RFS",
            "zone_diameter_m": zone,
            "bonus_m": bonus,
            "nominal_m": list(nominal),
            "actual_m": list(meas),
            "deviation_m": [dx, dy, dz],
            "value_m": value,
            "U_m": 3e-5,
            "decision": _decision(value, 3e-5, 0.0, zone + bonus),
            "reason": "",
        },
    ]


def _char_missing(hid: str, diameter: float) -> list[dict[str, Any]]:
    reason = f"hole {hid} was not measured (missing)"
    return [
        {
            "id": f"{hid}.diameter",
            "hole_id": hid,
            "kind": "diameter",
            "nominal_m": diameter,
            "upper_m": 2.2e-5,
            "lower_m": 0.0,
            "actual_m": None,
            "deviation_m": None,
            "value_m": None,
            "U_m": None,
            "decision": "not_evaluated",
            "reason": reason,
        },
        {
            "id": f"{hid}.position",
            "hole_id": hid,
            "kind": "position",
            "drf": "DRF1",
            "datums": ["A", "B", "C"],
            "material_condition": "RFS",
            "zone_diameter_m": 5e-4,
            "bonus_m": 0.0,
            "nominal_m": [0.0, 0.0, 0.0],
            "actual_m": None,
            "deviation_m": None,
            "value_m": None,
            "U_m": None,
            "decision": "not_evaluated",
            "reason": reason,
        },
    ]
