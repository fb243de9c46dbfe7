"""A run's measured holes into datum reference frames, the placement and the characteristics
of report.json (field names: docs/gdt.md; the interface with the QIF writer).

Order: which datum features were measured -> every DRF the tolerances name (and the run's
alignment) from the draws of the measured centres (:mod:`cell.gdt.montecarlo`; draw 0 is the
estimate) -> per hole with tolerances its position (in its DRF) and size characteristics with
their U and ISO 14253-1 decisions (:mod:`cell.gdt.decide`). A DRF whose datum feature was not
measured is not evaluated, and neither is any characteristic that needs it: no fallback to the
fixture frame. A cell without datums (no ``part.datums``, no ``part.alignment``) is evaluated
in the fixture frame (``part.base``), as it declares; its placement is then estimated by a
least-squares best fit over every measured hole and reported, not used.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation

from cell.config import CellConfig, Hole
from cell.config.datums import Datum
from cell.gdt.align import Frames, best_fit_frame, datum_frame
from cell.gdt.decide import (
    NOT_EVALUATED,
    decide_interval,
    decide_upper,
)
from cell.gdt.errors import GdtError
from cell.gdt.montecarlo import McOptions, draw_centres, expanded
from cell.records.hole_result import HoleResult
from cell.uncertainty.decision import DEFAULT_RULE

FIXTURE = "fixture"


@dataclass
class Evaluation:
    """The report.json fields of :mod:`cell.gdt` (``datum_reference_frames``, ``datums``,
    ``placement``, ``characteristics``) and the alignment's name (a DRF id, ``ALIGN`` for a best
    fit, or ``fixture``)."""

    datum_reference_frames: list[dict[str, Any]]
    datums: list[dict[str, Any]]
    placement: dict[str, Any] | None
    characteristics: list[dict[str, Any]]
    alignment: str
    frames: dict[str, tuple[Frames, Frames]] = field(default_factory=dict, repr=False)
    reason: str = ""
    #: holes without a position characteristic, in the alignment (:meth:`_Run.hole_deviations`)
    hole_deviations: dict[str, Any] = field(default_factory=dict)

    def fields(self) -> dict[str, Any]:
        """The mapping added to report.json."""
        return {"alignment": self.alignment, "gdt_reason": self.reason,
                "datum_reference_frames": self.datum_reference_frames, "datums": self.datums,
                "placement": self.placement, "characteristics": self.characteristics}  # fmt: skip


def _pose(R: np.ndarray, t: np.ndarray) -> dict[str, list[float]]:
    return {"xyz": [float(v) for v in t],
            "quat_xyzw": [float(v) for v in Rotation.from_matrix(R).as_quat()]}  # fmt: skip


def _pose_U(R: np.ndarray, t: np.ndarray, k: float = 2.0) -> tuple[list[float], list[float]]:
    """Expanded (k = 2) uncertainty per axis of draws ``R (N,3,3)``, ``t (N,3)`` about draw 0:
    of the position (m) and of the rotation vector of ``R_r R_0^T`` (rad)."""
    if len(t) < 3:
        return [0.0] * 3, [0.0] * 3
    rv = Rotation.from_matrix(np.einsum("nij,kj->nik", R[1:], R[0])).as_rotvec()
    return ([float(v) for v in k * np.std(t[1:] - t[0], axis=0)],
            [float(v) for v in k * np.std(rv, axis=0)])  # fmt: skip


def _not_measured(cell: CellConfig, results: dict[str, HoleResult], ids: list[str]) -> str:
    """Why holes ``ids`` were not measured ('' when all were)."""
    out = []
    for h in ids:
        r = results.get(h)
        if r is None:
            out.append(f"{h} not measured (not in the tour or not reached)")
        elif not r.measured:
            out.append(f"{h} {r.status}: {r.reason}")
    return "; ".join(out)


class _Run:
    """One evaluation: the cell, the results by hole, the draws and the frames built so far."""

    def __init__(self, cell: CellConfig, results: list[HoleResult], opts: McOptions) -> None:
        self.cell, self.opts = cell, opts
        self.results = {r.hole_id: r for r in results}
        self.rule = next((r.decision_rule for r in results if r.decision_rule), DEFAULT_RULE)
        self.holes = {h.id: h for h in cell.part.holes}
        self.nominal = {h.id: np.asarray(h.position, float) for h in cell.part.holes}
        self.normals = {h.id: np.asarray(h.normal, float) for h in cell.part.holes}
        self.draws = draw_centres(results, opts.n_draws + 1, opts.seed)
        self.datum = {d.label: d for d in cell.part.datums}
        self.frames: dict[str, tuple[Frames, Frames]] = {}  # id -> (actual draws, nominal)
        self.nominal_frames: dict[str, Frames] = {}  # id -> nominal DRF (whatever was measured)
        self.drfs: list[dict[str, Any]] = []
        self.by_labels: dict[tuple[str, ...], str] = {}

    def datum_records(self) -> list[dict[str, Any]]:
        out = []
        for d in self.cell.part.datums:
            why = _not_measured(self.cell, self.results, d.hole_ids())
            out.append({"label": d.label, "kind": d.kind, "holes": d.hole_ids(),
                        "measured": not why, "reason": why})  # fmt: skip
        return out

    def drf(self, labels: tuple[str, ...]) -> str:
        """The id of the DRF of ``labels`` (built on first use)."""
        if labels in self.by_labels:
            return self.by_labels[labels]
        drf_id = f"DRF{len(self.by_labels) + 1}"
        self.by_labels[labels] = drf_id
        datums = [self.datum[lab] for lab in labels]
        rec: dict[str, Any] = {"id": drf_id, "datums": list(labels)}
        nominal = {k: v[None] for k, v in self.nominal.items()}
        self.nominal_frames[drf_id] = datum_frame(datums, nominal, self.nominal, self.normals)
        why = "; ".join(f"datum {d.label}: {w}" for d in datums
                        if (w := _not_measured(self.cell, self.results, d.hole_ids())))  # fmt: skip
        if not why:
            try:
                self.frames[drf_id] = self._frames(datums)
            except GdtError as exc:
                why = str(exc)
        self.drfs.append({**rec, **self._drf_fields(drf_id, why)})
        return drf_id

    def _frames(self, datums: list[Datum]) -> tuple[Frames, Frames]:
        actual = datum_frame(datums, self.draws, self.nominal, self.normals)
        return actual, self.nominal_frames[self.by_labels[tuple(d.label for d in datums)]]

    def _drf_fields(self, drf_id: str, why: str) -> dict[str, Any]:
        if drf_id not in self.frames:
            return {"status": "not_evaluated", "reason": why, "T_part_drf": None,
                    "U_T_part_drf": None, "residuals_m": {}}  # fmt: skip
        act, nom = self.frames[drf_id]
        Uxyz, Urot = _pose_U(act.R, act.t)
        return {"T_part_drf": _pose(act.R[0], act.t[0]),
                "T_part_drf_nominal": _pose(nom.R[0], nom.t[0]),
                "U_T_part_drf": {"xyz_m": Uxyz, "rotation_rad": Urot},
                "residuals_m": self._residuals(drf_id), "status": "evaluated",
                "reason": ""}  # fmt: skip

    def _residuals(self, drf_id: str) -> dict[str, float]:
        """Each datum feature's fit RMS (m): a plane's or a pattern's from the alignment, a
        single hole's its own circle fit's."""
        act = self.frames[drf_id][0]
        out = {lab: float(v[0]) for lab, v in act.residuals_m.items()}
        for lab in out:
            d = self.datum.get(lab)
            if d is not None and d.kind == "hole":
                out[lab] = float(self.results[d.hole].rms_m or 0.0)
        return out

    def best_fit(self) -> str:
        bf = self.cell.part.alignment.best_fit
        ids = [h for h in (bf.holes or list(self.holes)) if h in self.draws]
        rec: dict[str, Any] = {"id": "ALIGN", "datums": [], "kind": f"best_fit:{bf.method}",
                               "holes": ids}  # fmt: skip
        why = _not_measured(self.cell, self.results, list(bf.holes)) if bf.holes else ""
        if len(ids) < 3:
            why = why or "fewer than 3 measured holes for a best fit"
        if not why:
            self.frames["ALIGN"] = self._best_fit_frames(ids, bf.method)
        self.drfs.append({**rec, **self._drf_fields("ALIGN", why)})
        return "ALIGN"

    def _best_fit_frames(self, ids: list[str], method: str) -> tuple[Frames, Frames]:
        n = self.opts.n_draws_minimax + 1 if method == "minimax" else None
        draws = {h: self.draws[h][:n] for h in ids}
        nominal = {h: self.nominal[h][None] for h in ids}
        act = best_fit_frame(ids, draws, self.nominal, method)
        return act, best_fit_frame(ids, nominal, self.nominal, "least_squares")

    def alignment(self) -> str:
        a = self.cell.part.alignment
        if a is not None and a.best_fit is not None:
            return self.best_fit()
        if a is not None and a.datums is not None:
            return self.drf(tuple(a.datums))
        for h in self.cell.part.holes:
            if h.tolerances and h.tolerances.position:
                return self.drf(tuple(h.tolerances.position.datums))
        return FIXTURE

    def placement(self, align: str) -> dict[str, Any] | None:
        """The part on its fixture: ``T_fixture_part = T_part_drf T_part_drf_nominal^-1``."""
        method = f"alignment {align}"
        if align == FIXTURE:
            ids = [h for h in self.holes if h in self.draws]
            if len(ids) < 3:
                return None
            frames = best_fit_frame(ids, {h: self.draws[h] for h in ids}, self.nominal,
                                    "least_squares"), None  # fmt: skip
            method = f"least-squares best fit over {len(ids)} holes (reported, not used)"
        elif align in self.frames:
            frames = self.frames[align]
        else:
            return {
                "T_fixture_part": None,
                "U_xyz_m": None,
                "U_rotation_rad": None,
                "method": method,
                "status": "not_evaluated",
                "reason": next(d["reason"] for d in self.drfs if d["id"] == align),
            }
        act, nom = frames
        R, t = act.R, act.t
        if nom is not None:
            Rn, tn = nom.R[0], nom.t[0]
            R = np.einsum("nij,kj->nik", act.R, Rn)
            t = act.t - np.einsum("nij,j->ni", R, tn)
        Uxyz, Urot = _pose_U(R, t)
        return {"T_fixture_part": _pose(R[0], t[0]), "U_xyz_m": Uxyz, "U_rotation_rad": Urot,
                "method": method, "status": "evaluated", "reason": ""}  # fmt: skip

    def characteristics(self, align: str) -> list[dict[str, Any]]:
        out: list[dict[str, Any]] = []
        for h in self.cell.part.holes:
            pos, size = _specs(h)
            legacy = {"legacy": h.tolerances is None}
            if pos is not None:
                labels = tuple(pos["datums"])
                drf_id = self.drf(labels) if labels else align
                out.append({**self._position(h, pos, size, drf_id), **legacy})
            if size is not None:
                out.append({**self._size(h, size), **legacy})
        return out

    def _position(self, h: Hole, pos: dict, size: dict | None, drf_id: str) -> dict[str, Any]:
        rec = {"id": f"{h.id}.position", "hole_id": h.id, "kind": "position", "drf": drf_id,
               "datums": list(pos["datums"]), "material_condition": pos["material_condition"],
               "zone_diameter_m": pos["zone_diameter_m"], "bonus_m": 0.0,
               **_drawing_name(pos)}  # fmt: skip
        r = self.results.get(h.id)
        why = _not_measured(self.cell, self.results, [h.id])
        if not why and drf_id != FIXTURE and drf_id not in self.frames:
            why = f"{drf_id} not evaluated: " + next(d["reason"] for d in self.drfs
                                                     if d["id"] == drf_id)  # fmt: skip
        if why:
            nom = self.nominal_frames.get(drf_id)
            nominal = (list(h.position) if nom is None  # the fixture frame: the part's own
                       else nom.to_drf(self.nominal[h.id][None])[0].tolist())  # fmt: skip
            return {**rec, **_blank("position"), "nominal_m": nominal, "reason": why}
        d = self.deviation(h.id, drf_id)
        values, U = d["values"], d["U_m"]
        bonus, limit, U_dec = 0.0, pos["zone_diameter_m"], U
        if pos["material_condition"] != "RFS" and size is not None:
            bonus = _bonus(h, r, pos["material_condition"], size)
            limit += bonus
            if bonus > 0.0:
                U_dec = float(np.hypot(U, r.U_diameter_m or 0.0))
        return {**rec, "bonus_m": bonus, **d["fields"], "value_m": float(values[0]),
                "U_m": U, "decision": decide_upper(float(values[0]), U_dec, limit, self.rule),
                "reason": ""}  # fmt: skip

    def deviation(self, hole_id: str, drf_id: str) -> dict[str, Any]:
        """A measured hole in a frame: the draws of its position value 2|P d| (m), its U and
        the fields nominal, actual, deviation, axial deviation and nominal axis (DRF, m)."""
        if drf_id == FIXTURE:
            n = len(self.draws[hole_id])
            act = Frames(np.repeat(np.eye(3)[None], n, 0), np.zeros((n, 3)), {})
            nom = Frames(np.eye(3)[None], np.zeros((1, 3)), {})
        else:
            act, nom = self.frames[drf_id]
        nominal = nom.to_drf(self.nominal[hole_id][None])[0]
        axis = nom.R[0].T @ self.normals[hole_id]
        actual = act.to_drf(self.draws[hole_id][: len(act.t)])
        dev = actual - nominal
        values = 2.0 * np.linalg.norm(dev @ (np.eye(3) - np.outer(axis, axis)), axis=1)
        fields = {"nominal_m": [float(v) for v in nominal],
                  "actual_m": [float(v) for v in actual[0]],
                  "deviation_m": [float(v) for v in dev[0]],
                  "axial_deviation_m": float(dev[0] @ axis),
                  "axis_drf": [float(v) for v in axis]}  # fmt: skip
        return {
            "values": values,
            "U_m": expanded(values[1:], values[0], self.opts.coverage),
            "fields": fields,
        }

    def hole_deviations(self, align: str, chars: list[dict[str, Any]]) -> dict[str, Any]:
        """The holes without a position characteristic, in the run's alignment: the ISO 1101
        position value (the diameter 2 |d| of the zone about the nominal axis holding the
        centre, m), its U and the axial deviation, or the reason there is none."""
        with_position = {c["hole_id"] for c in chars if c["kind"] == "position"}
        out: dict[str, Any] = {}
        for h in self.cell.part.holes:
            if h.id in with_position or h.id not in self.results:
                continue
            why = _not_measured(self.cell, self.results, [h.id])
            if not why and align != FIXTURE and align not in self.frames:
                why = f"alignment {align} not evaluated"
            if why:
                out[h.id] = {"frame": align, "reason": why}
                continue
            d = self.deviation(h.id, align)
            out[h.id] = {
                "frame": align,
                "position_m": float(d["values"][0]),
                "U_position_m": d["U_m"],
                "axial_deviation_m": d["fields"]["axial_deviation_m"],
                "reason": "",
            }
        return out

    def _size(self, h: Hole, size: dict) -> dict[str, Any]:
        rec = {
            "id": f"{h.id}.diameter",
            "hole_id": h.id,
            "kind": "diameter",
            "nominal_m": h.diameter,
            "upper_m": size["upper_m"],
            "lower_m": size["lower_m"],
            **_drawing_name(size),
        }
        r = self.results.get(h.id)
        why = _not_measured(self.cell, self.results, [h.id])
        if why:
            return {**rec, **_blank("diameter"), "reason": why}
        dev = float(r.diameter_m - h.diameter)
        U = float(r.U_diameter_m or 0.0)
        return {**rec, "actual_m": r.diameter_m, "deviation_m": dev, "value_m": r.diameter_m,
                "U_m": U, "decision": decide_interval(dev, U, size["lower_m"], size["upper_m"],
                                                      self.rule), "reason": ""}  # fmt: skip


def _blank(kind: str) -> dict[str, Any]:
    base = {"actual_m": None, "deviation_m": None, "value_m": None, "U_m": None,
            "decision": NOT_EVALUATED}  # fmt: skip
    return {**base, "nominal_m": None} if kind == "position" else base


def _drawing_name(spec: dict) -> dict[str, str]:
    """``{"pmi_id": ...}`` when the tolerance carries the drawing's name (AP242 PMI), else {}."""
    return {"pmi_id": spec["pmi_id"]} if spec.get("pmi_id") else {}


def _specs(h: Hole) -> tuple[dict | None, dict | None]:
    """A hole's position and size specifications; the old single ``tolerance`` t reads as a
    position zone of diameter 2t in the run's alignment and a size of +-t."""
    if h.tolerances is not None:
        p, s = h.tolerances.position, h.tolerances.size
        return (None if p is None else p.model_dump()), (None if s is None else s.model_dump())
    if h.tolerance is not None:
        t = h.tolerance
        return ({"zone_diameter_m": 2 * t, "datums": [], "material_condition": "RFS"},
                {"upper_m": t, "lower_m": -t})  # fmt: skip
    return None, None


def _bonus(h: Hole, r: HoleResult, condition: str, size: dict) -> float:
    """The bonus tolerance (m): at MMC the measured diameter above the hole's MMC size (its
    smallest, nominal + lower), at LMC below its LMC size (its largest); never negative. The
    size used is the circle fit's diameter at the rim (docs/gdt.md)."""
    if condition == "MMC":
        return max(0.0, float(r.diameter_m - (h.diameter + size["lower_m"])))
    return max(0.0, float(h.diameter + size["upper_m"] - r.diameter_m))


def evaluate(cell: CellConfig, results: list[HoleResult],
             opts: McOptions | None = None) -> Evaluation:  # fmt: skip
    """The GD&T evaluation of a run's ``results`` against ``cell``'s datums and tolerances."""
    run = _Run(cell, results, opts or McOptions())
    datums = run.datum_records()
    align = run.alignment()
    chars = run.characteristics(align)
    ev = Evaluation(run.drfs, datums, run.placement(align), chars, align, run.frames)
    ev.hole_deviations = run.hole_deviations(align, chars)
    return ev
