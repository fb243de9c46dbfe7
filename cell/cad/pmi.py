"""The semantic PMI of a STEP file (AP242 GD&T, read by OpenCascade into the XCAF document):
datums, position tolerances and diameter size tolerances, matched to the holes found by the
faces they are attached to, as the cell file writes them (:mod:`cell.config.datums`).

Kept, with the PMI's name as ``pmi_id``:
- a datum on a hole's measured bore: ``hole: ID``; on several holes' bores: ``pattern: [IDs]``;
  on a plane: ``plane: {holes: [...]}`` through the holes whose entry centres lie on it (>= 3);
- a position tolerance on a hole: ``position: {zone_diameter_m, datums, material_condition}``
  and a diameter dimension with limits: ``size: {upper_m, lower_m}``
  (:mod:`cell.cad.pmi_tolerances`); a position at MMC or LMC only with the hole's size.

Where XCAF attaches a datum to no face, its faces are read from the STEP entity graph
(:mod:`cell.cad.pmi_graph`; said in ``notes``). Everything else (datum targets; form,
orientation, profile, runout tolerances; linear and angular dimensions; tolerances on faces
that are no hole or another bore than the measured one) is listed in ``unmodelled``, one line
each, never dropped silently.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from OCP.TDF import TDF_Label
from OCP.XCAFDimTolObjects import (
    XCAFDimTolObjects_DimensionType_CommonLabel as COMMON_LABEL,
)
from OCP.XCAFDimTolObjects import (
    XCAFDimTolObjects_DimensionType_DimensionPresentation as PRESENTATION,
)
from OCP.XCAFDoc import XCAFDoc_Datum, XCAFDoc_Dimension, XCAFDoc_DocumentTool

from cell.cad.holes import CadHole
from cell.cad.pmi_doc import Pmi, PmiFaces, attr, holes_of, labels
from cell.cad.pmi_graph import FaceLocator, StepGraph
from cell.cad.pmi_tolerances import SAME_SIZE_M, dimension, tolerance
from cell.cad.step_read import StepDocument

__all__ = ["Pmi", "read_pmi"]

#: a hole's entry lies on a datum plane within this (m)
ON_PLANE_M = 1e-6


def _datum_feature(
    label: str, faces: list[int], geo: PmiFaces, holes: list[CadHole]
) -> tuple[dict[str, Any] | None, str]:
    """The cell-file datum for faces, or None and why not."""
    on = holes_of(faces, holes)
    other = [
        f"{h.id} (its {b * 1e3:g} mm bore; the {h.diameter_m * 1e3:g} mm entry bore is measured)"
        for h in on
        if (b := geo.bore_of(h, faces)) is not None and abs(b - h.diameter_m) > SAME_SIZE_M
    ]
    if other:
        return None, f"on another bore than the measured one: {', '.join(other)}"
    if len(on) == 1:
        return {"label": label, "hole": on[0].id}, ""
    if on:
        return {"label": label, "pattern": [h.id for h in on]}, ""
    planes = [geo.plane(i) for i in faces]
    if faces and all(p is not None for p in planes):
        p, n = planes[0]  # type: ignore[misc]
        rims = [h.id for h in holes if abs(float(np.dot(np.array(h.entry_m) - p, n))) <= ON_PLANE_M]
        if len(rims) >= 3:
            return {"label": label, "plane": {"holes": rims}}, ""
        return None, (
            f"a plane with {len(rims)} hole entries on it (the cell's plane datum is the plane "
            "through >= 3 measured entry rims)"
        )
    return None, "not on a hole or a plane" if faces else "attached to no face"


class _Graph:
    """The STEP entity graph, read only when the PMI needs it."""

    def __init__(self, doc: StepDocument, geo: PmiFaces, holes: list[CadHole]) -> None:
        self.doc, self.geo, self.holes = doc, geo, holes
        self.graph: StepGraph | None = None
        self.locator: FaceLocator | None = None

    def _read(self) -> StepGraph:
        if self.graph is None:
            self.graph = StepGraph(self.doc.path)
        return self.graph

    def capped(self) -> set[str]:
        """The names of the tolerances with a maximum value (``MAX``) in the file."""
        return self._read().capped

    def faces(self, letter: str) -> tuple[list[int], int, int]:
        """The face numbers of datum ``letter`` in the entity graph, its number of datum
        targets, and the number of its face entities not found in the shape."""
        if self.doc.reader is None:
            return [], 0, 0
        if self.locator is None:
            walls = sorted({k for h in self.holes for k in h.faces})
            self.locator = FaceLocator(self.doc.reader, self._read(), self.geo.map, walls)
        found = self.locator.graph.features(letter)
        faces, missing = self.locator.locate(found.faces)
        return faces, found.targets, len(missing)


def _datums(gdt, geo: PmiFaces, holes: list[CadHole], pmi: Pmi, graph: _Graph) -> None:
    """Fill ``pmi.datums`` (module doc)."""
    faces_of: dict[str, list[int]] = {}
    targets: dict[str, int] = {}
    for lab in labels(gdt.GetDatumLabels):
        obj = attr(lab, XCAFDoc_Datum).GetObject()
        name = obj.GetName().ToCString()
        faces_of.setdefault(name, []).extend(geo.of(lab))
        targets[name] = targets.get(name, 0) + int(obj.IsDatumTarget())
    for name, faces in faces_of.items():
        if not faces:
            faces, n_targets, missing = graph.faces(name)
            targets[name] = max(targets[name], n_targets)
            if faces:
                pmi.notes.append(
                    f"datum {name}: {len(faces)} faces read from the STEP entity graph "
                    "(OpenCascade's XCAF attaches it to none)"
                    + (f"; {missing} face entities not found in the shape" if missing else "")
                )
        if not faces and targets[name]:
            pmi.unmodelled.append(
                f"datum {name}: {targets[name]} datum targets (points, lines or areas; the "
                "cell's datums are holes, hole patterns and planes through hole rims)"
            )
            continue
        datum, why = _datum_feature(name, sorted(set(faces)), geo, holes)
        if datum is None:
            pmi.unmodelled.append(f"datum {name}: {why}")
        else:
            pmi.datums.append({**datum, "pmi_id": f"datum {name}"})


def _graphical(label: TDF_Label) -> bool:
    """Whether a dimension label is presentation only (a drawn annotation without values)."""
    kind = attr(label, XCAFDoc_Dimension).GetObject().GetType()
    return kind in (PRESENTATION, COMMON_LABEL)


def _sizes_for_conditions(pmi: Pmi) -> None:
    """A position at MMC or LMC needs the hole's size limits: without them it is listed."""
    for hid, tol in list(pmi.tolerances.items()):
        pos = tol.get("position")
        if pos is not None and pos["material_condition"] != "RFS" and "size" not in tol:
            pmi.unmodelled.append(
                f"{pos['pmi_id']} on {hid}: at {pos['material_condition']}, but the hole has no "
                "size tolerance to give its bonus"
            )
            del tol["position"]
        if not tol:
            del pmi.tolerances[hid]


def read_pmi(doc: StepDocument, holes: list[CadHole]) -> Pmi:
    """The PMI of ``doc`` matched to ``holes`` (module doc)."""
    gdt = XCAFDoc_DocumentTool.DimTolTool_s(doc.doc.Main())
    tol_labels = labels(gdt.GetGeomToleranceLabels)
    all_dims = labels(gdt.GetDimensionLabels)
    dim_labels = [d for d in all_dims if not _graphical(d)]
    datum_labels = labels(gdt.GetDatumLabels)
    pmi = Pmi(semantic=bool(tol_labels or dim_labels or datum_labels))
    pmi.counts = {
        "geometric tolerances": len(tol_labels),
        "dimensions": len(dim_labels),
        "datum labels": len(datum_labels),
        "graphical only": len(all_dims) - len(dim_labels),
    }
    if pmi.counts["graphical only"]:
        pmi.unmodelled.append(
            f"{pmi.counts['graphical only']} graphical annotations (presentation only, no "
            "semantic value)"
        )
    if not pmi.semantic:
        return pmi
    geo = PmiFaces(doc)
    graph = _Graph(doc, geo, holes)
    _datums(gdt, geo, holes, pmi, graph)
    capped = graph.capped() if tol_labels else set()
    for lab in tol_labels:
        tolerance(lab, geo, holes, pmi, capped)
    for lab in dim_labels:
        dimension(lab, geo, holes, pmi)
    _sizes_for_conditions(pmi)
    return pmi
