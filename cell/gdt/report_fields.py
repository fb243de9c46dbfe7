"""The evaluation into report.json and the summary: the cell a run was made with, the per-hole
fields readers already know (``position_m``, ``U_position_m``, ``decision``,
``pass``, ``status``) taken from the characteristics, and the summary's counts.

One position convention everywhere (ISO 1101): a position is the diameter ⌀ of the zone about
the nominal axis that holds the centre, 2 × the centre's in-plane distance from its nominal.
Per hole with a position characteristic, ``position_m`` is its value (in its DRF,
``position_frame``) and ``U_position_m`` its U; the fixture-frame value of the run stays in the
characteristic as ``position_fixture_m``. A hole whose characteristics were not evaluated has no
position deviation, no U and no decision (its reason says why). A cell evaluated in the
fixture frame keeps every per-hole field of the run as it was.
"""

from __future__ import annotations

import contextlib
from dataclasses import replace
from pathlib import Path
from typing import Any

import yaml
from pydantic import ValidationError

from cell.config import CellConfig
from cell.config.load import _with_csv_holes, _with_step
from cell.errors import CellError, ConfigError
from cell.gdt.decide import CONFORMANCE, INDETERMINATE, NONCONFORMANCE, NOT_EVALUATED, hole_decision
from cell.gdt.evaluate import FIXTURE, Evaluation, evaluate
from cell.records.hole_result import HoleResult
from cell.uncertainty.decision import CONFORMING, INCONCLUSIVE, NONCONFORMING

CHARACTERISTIC_DECISIONS = (CONFORMANCE, INDETERMINATE, NONCONFORMANCE, NOT_EVALUATED)


def run_cell(info: dict[str, Any]) -> CellConfig:
    """The cell a run was made with, from the store's copy of the cell file (validated as a
    cell file, without building the robot again: it was built when the run started)."""
    cfg = CellConfig.model_validate(yaml.safe_load(info["cell_text"]))
    path = Path(info["cell_path"]) if info.get("cell_path") else None
    cfg._source_path, cfg._raw_text = path, info["cell_text"]
    if cfg.part.holes_csv is not None:
        # a CSV that is gone: its holes get no characteristics, the rest are kept
        with contextlib.suppress(ConfigError, OSError):
            cfg = _with_csv_holes(cfg, str(path), path, info["cell_text"])
    if cfg.part.step is not None:
        # likewise a STEP file that is gone (CellError: it no longer parses)
        with contextlib.suppress(CellError, OSError):
            cfg = _with_step(cfg, path, info["cell_text"])
    return cfg


def apply_to_rows(ev: Evaluation, rows: list[dict[str, Any]]) -> None:
    """Set the per-hole fields of report rows from the characteristics (see module doc); the
    holes of the old single ``tolerance`` evaluated in the fixture frame keep the run's."""
    by_hole: dict[str, list[dict[str, Any]]] = {}
    for c in ev.characteristics:
        by_hole.setdefault(c["hole_id"], []).append(c)
    for row in rows:
        chars = by_hole.get(row["hole_id"], [])
        if ev.alignment == FIXTURE and all(c["legacy"] for c in chars):
            continue
        other = ev.hole_deviations.get(row["hole_id"])
        if other is not None and row["position_m"] is not None:
            row["position_m"] = other.get("position_m")
            row["U_position_m"] = other.get("U_position_m")
            row["position_frame"] = other["frame"]
            row["axial_deviation_m"] = other.get("axial_deviation_m")
            if other["reason"]:
                row["reason"] = "; ".join(filter(None, [row["reason"], other["reason"]]))
        if chars:
            _apply_one(row, chars)


def _apply_one(row: dict[str, Any], chars: list[dict[str, Any]]) -> None:
    for c in chars:
        if c["kind"] == "position":
            c["position_fixture_m"] = row["position_m"]
            row["position_m"] = c["value_m"]
            row["U_position_m"] = c["U_m"]
            row["position_frame"] = c["drf"]
            row["axial_deviation_m"] = c.get("axial_deviation_m")
    decisions = [c["decision"] for c in chars]
    row["decision"] = hole_decision(decisions)
    if NOT_EVALUATED in decisions:
        row["pass"] = None
        row["reason"] = "; ".join(
            filter(
                None,
                [row["reason"]]
                + [f"{c['id']} not evaluated: {c['reason']}" for c in chars if c["reason"]],
            )
        )
    elif row["pass"] is not None:
        ok = all(_within(c) for c in chars)
        row["pass"] = ok
        if row["status"] in ("ok", "fail"):
            row["status"] = "ok" if ok else "fail"


def _within(c: dict[str, Any]) -> bool:
    """Shared acceptance (U ignored): the value within its specification."""
    if c["kind"] == "position":
        return c["value_m"] <= c["zone_diameter_m"] + c["bonus_m"]
    return c["lower_m"] <= c["deviation_m"] <= c["upper_m"]


def apply_to_summary(ev: Evaluation, rows: list[dict[str, Any]], summ: dict[str, Any]) -> None:
    """Recount the summary's hole decisions and extremes from the rows; add the
    characteristics' counts and the alignment."""
    measured = [r for r in rows if r["position_m"] is not None]
    worst = max(measured, key=lambda r: r["position_m"], default=None)
    U = [r["U_position_m"] for r in measured if r["U_position_m"] is not None]
    summ.update({
        "holes_failed": sum(r["pass"] is False for r in rows),
        "holes_conforming": sum(r["decision"] == CONFORMING for r in rows),
        "holes_inconclusive": sum(r["decision"] == INCONCLUSIVE for r in rows),
        "holes_nonconforming": sum(r["decision"] == NONCONFORMING for r in rows),
        "worst_position_m": worst["position_m"] if worst else None,
        "worst_hole": worst["hole_id"] if worst else None,
        "worst_position_frame": worst["position_frame"] if worst else None,
        "max_U_position_m": max(U, default=None),
        "alignment": ev.alignment,
        "characteristics": {d: sum(c["decision"] == d for c in ev.characteristics)
                            for d in CHARACTERISTIC_DECISIONS},
    })  # fmt: skip


def report_evaluation(info: dict[str, Any], results: list[HoleResult], rows: list[dict[str, Any]],
                      summ: dict[str, Any]) -> tuple[Evaluation, list[HoleResult]]:  # fmt: skip
    """Evaluate a run for its report: the evaluation, with ``rows`` and ``summ`` updated in
    place, and the results with the same per-hole fields (for report.html's hole table)."""
    try:
        cell = run_cell(info)
    except (ValidationError, yaml.YAMLError, TypeError, KeyError) as exc:
        why = f"the run's stored cell file is not a readable cell file ({str(exc).splitlines()[0]})"
        return Evaluation([], [], None, [], FIXTURE, reason=why), results
    ev = evaluate(cell, results)
    apply_to_rows(ev, rows)
    apply_to_summary(ev, rows, summ)
    by_id = {row["hole_id"]: row for row in rows}
    keys = ("axial_deviation_m", "decision", "status", "reason")
    out = [replace(r, passed=by_id[r.hole_id]["pass"], **_radial(by_id[r.hole_id]),
                   **{k: by_id[r.hole_id][k] for k in keys}) for r in results]  # fmt: skip
    return ev, out


def _radial(row: dict[str, Any]) -> dict[str, Any]:
    """A row's position and U (⌀) as a :class:`HoleResult`'s in-plane distance and its U."""
    half = {k: None if row[k] is None else row[k] / 2.0 for k in ("position_m", "U_position_m")}
    return {"position_deviation_m": half["position_m"], "U_position_m": half["U_position_m"]}
