"""``report.json`` and ``report.csv`` of a run directory, from its store.

Files are in SI units (m); the printed summary is for people (mm, µm). report.json's ``holes``
rows: ``hole_id, stop, status, nominal_x_m .. nominal_z_m, measured_x_m .. measured_z_m,
position_m, position_frame, nominal_diameter_m, diameter_m, diameter_deviation_m, tolerance_m,
pass, u_center_m, u_diameter_m, reason, thermal_model_id, axial_deviation_m, U_position_m,
U_diameter_m, decision, decision_rule`` and one ``u_<component>_position_m`` /
``u_<component>_diameter_m`` pair per budget component (None where a hole was not measured;
``thermal_model_id``: the row of the store's ``thermal_models`` the hole was compensated with,
None for the nominal kinematics). report.csv: one row per characteristic
(:mod:`cell.review.report_csv`).

One position convention everywhere (ISO 1101): ``position_m`` is the diameter ⌀ of the zone
about the nominal axis that holds the centre, 2 × the centre's in-plane distance from its
nominal, in ``position_frame`` (``fixture``: the cell file's part frame; else a DRF id);
``U_position_m`` its expanded uncertainty, the ``u_<component>_position_m`` the in-plane
distance's. ``u_center_m`` / ``u_diameter_m`` are the circle fit's own one-sigma uncertainties
(kept for compatibility); ``U_*`` the expanded (k = 2) uncertainties of the whole budget
(:mod:`cell.uncertainty.budget`); positions and diameters are at 20 °C.
``referenced`` (report.json, report.csv): the stop was located against the surveyed markers
(True), fell back to the arm (False), or the run was not referenced (None, empty);
``reference_markers``: the markers the stop was located by, space-separated.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from cell.calibration.use import calibration_summary
from cell.gdt.report_fields import report_evaluation
from cell.records.hole_result import HoleResult
from cell.referencing.markersfile import MARKERS_FILENAME
from cell.review.audit_images import kept
from cell.review.gdt_html import gdt_section
from cell.review.qif.run_file import write_run_qif
from cell.review.referencing_html import referencing_section
from cell.review.report_csv import csv_rows, write_csv
from cell.review.report_html import render_html
from cell.review.store import Store
from cell.uncertainty.budget import COMPONENTS
from cell.uncertainty.decision import CONFORMING, INCONCLUSIVE, NONCONFORMING
from robots.files import write_text_atomic


def summary(store: Store) -> dict[str, Any]:
    """Counts and extremes of a run (SI units)."""
    info = store.run_info()
    results = store.results()
    planned = store.planned()
    measured = [r for r in results if r.measured]
    worst = max(measured, key=lambda r: r.position_deviation_m, default=None)
    U_pos = [r.U_position_m for r in measured if r.U_position_m is not None]
    return {
        "cell": info["cell_name"],
        "cell_sha256": info["cell_sha256"],
        "robot_model": info["robot_model"],
        "state": info["state"],
        "holes_planned": len(planned),
        "holes_stored": len(results),
        "holes_measured": len(measured),
        "holes_missing": sum(r.status == "missing" for r in results),
        "holes_unmeasured": sum(r.status == "unmeasured" for r in results),
        "holes_failed": sum(r.passed is False for r in results),
        "holes_suspect": sum(r.status == "suspect" for r in results),
        "holes_not_reached": len(planned) - len(results),
        "holes_conforming": sum(r.decision == CONFORMING for r in results),
        "holes_inconclusive": sum(r.decision == INCONCLUSIVE for r in results),
        "holes_nonconforming": sum(r.decision == NONCONFORMING for r in results),
        "decision_rule": next((r.decision_rule for r in results if r.decision_rule), None),
        "part": store.part_state(),
        **_referencing_counts(results),
        "calibration": calibration_summary(store.path.parent),
        "max_U_position_m": _twice(max(U_pos, default=None)),
        "max_U_diameter_m": max(
            (r.U_diameter_m for r in measured if r.U_diameter_m is not None), default=None
        ),
        "worst_position_m": _twice(worst.position_deviation_m) if worst else None,
        "worst_hole": worst.hole_id if worst else None,
        "worst_position_frame": "fixture" if worst else None,
        "worst_diameter_deviation_m": max(
            (abs(r.diameter_deviation_m) for r in measured), default=None
        ),
        "started_at": info["started_at"],
        "finished_at": info["finished_at"],
        "images": kept(store.path.parent),
    }


def _referencing_counts(results: list[HoleResult]) -> dict[str, Any]:
    """How many stops were located against the markers, fell back to the arm, or were flagged
    (the arm and the markers disagree by more than 1 mm); None when the run was not
    referenced."""
    refs = [r.extra["referencing"] for r in results if "referencing" in r.extra]
    if not refs:
        return {"holes_referenced": None, "holes_fallback": None, "holes_arm_disagreement": None}
    return {"holes_referenced": sum(bool(x.get("referenced")) for x in refs),
            "holes_fallback": sum(not x.get("referenced") for x in refs),
            "holes_arm_disagreement": sum((x.get("arm_registered_m") or 0.0) > 1e-3
                                          for x in refs)}  # fmt: skip


def _row(r: HoleResult) -> dict[str, Any]:
    nom = r.nominal_part_m
    meas = r.center_part_m or (None, None, None)
    return {
        "hole_id": r.hole_id,
        "stop": r.stop_index,
        "status": r.status,
        "nominal_x_m": nom[0], "nominal_y_m": nom[1], "nominal_z_m": nom[2],
        "measured_x_m": meas[0], "measured_y_m": meas[1], "measured_z_m": meas[2],
        "position_m": _twice(r.position_deviation_m),
        "position_frame": "fixture" if r.position_deviation_m is not None else None,
        "nominal_diameter_m": r.nominal_diameter_m,
        "diameter_m": r.diameter_m,
        "diameter_deviation_m": r.diameter_deviation_m,
        "tolerance_m": r.tolerance_m,
        "pass": r.passed,
        "u_center_m": r.u_center_m,
        "u_diameter_m": r.u_diameter_m,
        "reason": r.reason,
        "thermal_model_id": r.thermal_model_id,
        "axial_deviation_m": r.axial_deviation_m,
        "U_position_m": _twice(r.U_position_m),
        "U_diameter_m": r.U_diameter_m,
        "decision": r.decision,
        "decision_rule": r.decision_rule,
        **_referencing(r),
        **_components(r),
    }  # fmt: skip


def _referencing(r: HoleResult) -> dict[str, Any]:
    """Whether the stop was located against the markers, and by which."""
    ref = r.extra.get("referencing")
    if ref is None:
        return {"referenced": None, "reference_markers": None}
    return {"referenced": bool(ref.get("referenced")),
            "reference_markers": " ".join(ref.get("markers", [])) or None}  # fmt: skip


def _twice(v: float | None) -> float | None:
    """An in-plane distance as the ISO 1101 position value (⌀ of the zone, m)."""
    return None if v is None else 2.0 * v


def _components(r: HoleResult) -> dict[str, Any]:
    """The budget's components as ``u_<name>_position_m`` / ``u_<name>_diameter_m`` columns."""
    out: dict[str, Any] = {
        f"u_{c}_{q}_m": None for c in COMPONENTS for q in ("position", "diameter")
    }
    for c in (r.budget or {}).get("components", []):
        out[f"u_{c['name']}_position_m"] = c["u_position_m"]
        out[f"u_{c['name']}_diameter_m"] = c["u_diameter_m"]
    return out


def write_report(run_dir: str | Path, operator: str = "") -> dict[str, Any]:
    """Write ``report.json``, ``report.csv``, ``report.qif`` (QIF 3.0, :mod:`cell.review.qif`)
    and ``report.html`` (the inspection protocol,
    :mod:`cell.review.report_html`; ``operator`` fills its operator field) into ``run_dir``;
    returns the summary."""
    run_dir = Path(run_dir)
    with Store.open(run_dir) as store:
        summ = summary(store)
        results = store.results()
        rows = [_row(r) for r in results]
        events = store.events()
        info, planned = {**store.run_info(), "run_dir": str(run_dir)}, store.planned()
        reference = [(o[0], o[3]) for o in store.reference_observations()]
    gdt, results = report_evaluation(info, results, rows, summ)  # cell.gdt, docs/gdt.md
    html = render_html(summ, info, results, planned, operator, reference,
                       gdt_section(gdt.fields()), gdt.alignment == "fixture",
                       gdt.characteristics,
                       referencing_section(results, _markers_doc(run_dir)))  # fmt: skip
    write_text_atomic(run_dir / "report.html", html)
    doc = {"format": "holecell.report", "version": 1, "summary": summ, "holes": rows,
           "events": events, **gdt.fields()}  # fmt: skip
    (run_dir / "report.json").write_text(json.dumps(doc, indent=1))
    write_csv(run_dir / "report.csv", csv_rows(rows, gdt.characteristics, summ["decision_rule"]))
    write_run_qif(doc, run_dir, info, results)  # QIF 3.0 results (cell.review.qif)
    return summ


def _markers_doc(run_dir: Path) -> dict[str, Any] | None:
    """The run's copy of ``markers.json`` (a referenced run), or None."""
    path = run_dir / MARKERS_FILENAME
    if not path.exists():
        return None
    try:
        return json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None


def format_summary(summ: dict[str, Any]) -> str:
    """The human summary (mm, um)."""
    worst = summ["worst_position_m"]
    dia = summ["worst_diameter_deviation_m"]
    lines = [
        f"cell            {summ['cell']} ({summ['robot_model']})",
        f"run state       {summ['state']}",
        f"holes           {summ['holes_measured']} measured, {summ['holes_missing']} missing, "
        f"{summ['holes_unmeasured']} not measurable, "
        f"{summ['holes_failed']} out of tolerance, {summ['holes_suspect']} suspect, "
        f"{summ['holes_not_reached']} not reached "
        f"(of {summ['holes_planned']} planned)",
        f"decisions       {summ['holes_conforming']} conformance proven, "
        f"{summ['holes_inconclusive']} inconclusive, "
        f"{summ['holes_nonconforming']} nonconformance proven "
        f"(rule {summ['decision_rule'] or '-'})",
    ]
    chars = summ.get("characteristics")
    if chars:  # cell.gdt: the drawing's characteristics in the run's alignment
        lines.append(f"characteristics {chars['conformance']} conformance proven, "
                     f"{chars['inconclusive']} inconclusive, {chars['nonconformance']} "
                     f"nonconformance proven, {chars['not_evaluated']} not evaluated "
                     f"(alignment {summ['alignment']})")  # fmt: skip
    if summ.get("holes_referenced") is not None:
        lines.append(f"referencing     {summ['holes_referenced']} located against the markers, "
                     f"{summ['holes_fallback']} fell back to the arm, "
                     f"{summ['holes_arm_disagreement']} off the arm by over 1 mm")  # fmt: skip
    part = summ.get("part")
    if part:
        lines.append(f"part            {part['temperature_c']:.2f} degC "
                     f"+- {part['u_temperature_K']:.2f} K ({part['source']}), {part['material']}; "
                     "results at 20 degC")  # fmt: skip
    if worst is not None:
        lines.append(
            f"worst position  ⌀{worst * 1e3:.4f} mm (ISO 1101; hole "
            f"{summ['worst_hole']}, {summ['worst_position_frame']} frame)"
        )
        lines.append(f"worst diameter  {dia * 1e3:.4f} mm")
    images = summ.get("images")
    if images:
        lines.append(f"images kept     {images['pairs']} stereo pairs, "
                     f"{images['bytes'] / 1e6:.1f} MB lossless PNG in images/ "
                     "(holecell remeasure; --no-images keeps none)")  # fmt: skip
    if summ.get("max_U_position_m") is not None:
        lines.append(f"largest U (k=2) position ⌀{summ['max_U_position_m'] * 1e6:.1f} µm, "
                     f"diameter {summ['max_U_diameter_m'] * 1e6:.1f} µm")  # fmt: skip
    return "\n".join(lines)
