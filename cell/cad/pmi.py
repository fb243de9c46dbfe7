"""The semantic PMI of a STEP file (AP242 GD&T, read by OpenCascade into the XCAF document):
datums, position tolerances and diameter size tolerances, matched to the holes found by the
faces they are attached to, as the cell file writes them (:mod:`cell.config.datums`).

Kept, with the PMI's name as ``pmi_id``:
- a datum on a hole's wall: ``hole: ID``; on several holes' walls: ``pattern: [IDs]``; on a
  plane: ``plane: {holes: [...]}`` through the holes whose entry centres lie on it (>= 3);
- a position tolerance on a hole: ``position: {zone_diameter_m, datums, material_condition}``
  (zone and datums as the PMI gives them; a modifier M/L becomes MMC/LMC);
- a diameter dimension with limits on the measured bore: ``size: {upper_m, lower_m}``.

Everything else (form, orientation, profile, runout tolerances; linear and angular
dimensions; tolerances on faces that are no hole) is listed in
``unmodelled``, one line each, never dropped silently. OpenCascade gives a plus/minus
dimension's lower deviation as a magnitude; it is taken as below the nominal.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
from OCP.BRepAdaptor import BRepAdaptor_Surface
from OCP.GeomAbs import GeomAbs_Plane
from OCP.OCP.collections import Sequence_TDF_Label
from OCP.TDF import TDF_AttributeIterator, TDF_Label
from OCP.TopAbs import TopAbs_FACE
from OCP.TopExp import TopExp_Explorer
from OCP.TopoDS import TopoDS
from OCP.XCAFDimTolObjects import (
    XCAFDimTolObjects_DimensionType_CommonLabel as COMMON_LABEL,
)
from OCP.XCAFDimTolObjects import (
    XCAFDimTolObjects_DimensionType_DimensionPresentation as PRESENTATION,
)
from OCP.XCAFDimTolObjects import (
    XCAFDimTolObjects_DimensionType_Size_Diameter as SIZE_DIAMETER,
)
from OCP.XCAFDimTolObjects import (
    XCAFDimTolObjects_GeomToleranceMatReqModif_L as MOD_L,
)
from OCP.XCAFDimTolObjects import (
    XCAFDimTolObjects_GeomToleranceMatReqModif_M as MOD_M,
)
from OCP.XCAFDimTolObjects import (
    XCAFDimTolObjects_GeomToleranceType_Position as POSITION,
)
from OCP.XCAFDoc import (
    XCAFDoc_Datum,
    XCAFDoc_Dimension,
    XCAFDoc_DimTolTool,
    XCAFDoc_DocumentTool,
    XCAFDoc_GeomTolerance,
)

from cell.cad.cylinders import face_map
from cell.cad.holes import CadHole
from cell.cad.step_read import MM_TO_M, StepDocument

#: a hole's entry lies on a datum plane within this (m); a dimension names a bore within this
ON_PLANE_M = 1e-6
SAME_SIZE_M = 1e-6


@dataclass
class Pmi:
    """The PMI found: ``semantic`` False when the file has none; ``datums`` and per-hole
    ``tolerances`` as cell-file mappings; ``unmodelled`` one line per PMI left out."""

    semantic: bool = False
    datums: list[dict[str, Any]] = field(default_factory=list)
    tolerances: dict[str, dict[str, Any]] = field(default_factory=dict)
    unmodelled: list[str] = field(default_factory=list)
    counts: dict[str, int] = field(default_factory=dict)


def _attr(label: TDF_Label, cls: type) -> Any:
    it = TDF_AttributeIterator(label)
    while it.More():
        if isinstance(it.Value(), cls):
            return it.Value()
        it.Next()
    return None


def _labels(getter) -> list[TDF_Label]:
    seq = Sequence_TDF_Label()
    getter(seq)
    return [seq.Value(i + 1) for i in range(seq.Length())]


def _name(obj) -> str:
    n = obj.GetSemanticName()
    return "" if n is None else n.ToCString()


class _Faces:
    """The faces a PMI label is attached to, as face-map numbers."""

    def __init__(self, doc: StepDocument) -> None:
        self.shapes = XCAFDoc_DocumentTool.ShapeTool_s(doc.doc.Main())
        self.map = face_map(doc.shape)

    def of(self, label: TDF_Label) -> list[int]:
        first, second = Sequence_TDF_Label(), Sequence_TDF_Label()
        XCAFDoc_DimTolTool.GetRefShapeLabel_s(label, first, second)
        out: list[int] = []
        for i in range(first.Length()):
            shape = self.shapes.GetShape_s(first.Value(i + 1))
            ex = TopExp_Explorer(shape, TopAbs_FACE)
            while ex.More():
                k = self.map.FindIndex(ex.Current())
                if k > 0:
                    out.append(k)
                ex.Next()
        return out

    def plane(self, index: int) -> tuple[np.ndarray, np.ndarray] | None:
        """A planar face's point (m) and unit normal, None for another surface."""
        surf = BRepAdaptor_Surface(TopoDS.Face(self.map.FindKey(index)))
        if surf.GetType() != GeomAbs_Plane:
            return None
        pos = surf.Plane().Position()
        p, n = pos.Location(), pos.Direction()
        return np.array([p.X(), p.Y(), p.Z()]) * MM_TO_M, np.array([n.X(), n.Y(), n.Z()])


def _holes_of(faces: list[int], holes: list[CadHole]) -> list[CadHole]:
    return [h for h in holes if h.faces & set(faces)]


def _datum_feature(
    label: str, faces: list[int], geo: _Faces, holes: list[CadHole]
) -> tuple[dict[str, Any] | None, str]:
    """The cell-file datum for faces, or None and why not."""
    on = _holes_of(faces, holes)
    if on and len(on) == 1:
        return {"label": label, "hole": on[0].id}, ""
    if on:
        return {"label": label, "pattern": [h.id for h in on]}, ""
    planes = [geo.plane(i) for i in faces]
    if faces and all(p is not None for p in planes):
        p, n = planes[0]  # type: ignore[misc]
        rims = [h.id for h in holes if abs(float(np.dot(np.array(h.entry_m) - p, n))) <= ON_PLANE_M]
        if len(rims) >= 3:
            return {"label": label, "plane": {"holes": rims}}, ""
        return None, f"a plane with {len(rims)} hole rims on it (the cell's plane datum needs 3)"
    return None, "not on a hole or a plane" if faces else "attached to no face"


def _datums(gdt, geo: _Faces, holes: list[CadHole], pmi: Pmi) -> set[str]:
    """Fill ``pmi.datums``; the labels kept."""
    faces_of: dict[str, list[int]] = {}
    for lab in _labels(gdt.GetDatumLabels):
        obj = _attr(lab, XCAFDoc_Datum).GetObject()
        name = obj.GetName().ToCString()
        faces_of.setdefault(name, []).extend(geo.of(lab))
    kept: list[dict[str, Any]] = []
    for name, faces in faces_of.items():
        datum, why = _datum_feature(name, sorted(set(faces)), geo, holes)
        if datum is None:
            pmi.unmodelled.append(f"datum {name}: {why}")
        else:
            kept.append({**datum, "pmi_id": f"datum {name}"})
    pmi.datums = kept
    return {d["label"] for d in kept}


def read_pmi(doc: StepDocument, holes: list[CadHole]) -> Pmi:
    """The PMI of ``doc`` matched to ``holes`` (module doc)."""
    gdt = XCAFDoc_DocumentTool.DimTolTool_s(doc.doc.Main())
    tol_labels = _labels(gdt.GetGeomToleranceLabels)
    all_dims = _labels(gdt.GetDimensionLabels)
    dim_labels = [d for d in all_dims if not _graphical(d)]
    datum_labels = _labels(gdt.GetDatumLabels)
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
    geo = _Faces(doc)
    datums = _datums(gdt, geo, holes, pmi)
    for lab in tol_labels:
        _tolerance(gdt, lab, geo, holes, datums, pmi)
    for lab in dim_labels:
        _dimension(lab, geo, holes, pmi)
    return pmi


def _graphical(label: TDF_Label) -> bool:
    """Whether a dimension label is presentation only (a drawn annotation without values)."""
    kind = _attr(label, XCAFDoc_Dimension).GetObject().GetType()
    return kind in (PRESENTATION, COMMON_LABEL)


def _tolerance(gdt, lab, geo: _Faces, holes, datums: set[str], pmi: Pmi) -> None:
    obj = _attr(lab, XCAFDoc_GeomTolerance).GetObject()
    name = _name(obj) or "geometric tolerance"
    kind = str(obj.GetType()).rsplit("_", 1)[-1]
    value_mm = obj.GetValue()
    refs = []
    seq = Sequence_TDF_Label()
    XCAFDoc_DimTolTool.GetDatumWithObjectOfTolerLabels_s(lab, seq)
    for i in range(seq.Length()):
        d = _attr(seq.Value(i + 1), XCAFDoc_Datum).GetObject()
        refs.append((d.GetPosition(), d.GetName().ToCString()))
    labels = [n for _, n in sorted(refs)]
    on = _holes_of(geo.of(lab), holes)
    what = f"{name}: {kind} {value_mm:g} mm" + (f" |{'|'.join(labels)}" if labels else "")
    if obj.GetType() != POSITION:
        pmi.unmodelled.append(f"{what} (not modelled: the cell evaluates position and size)")
        return
    if not on:
        pmi.unmodelled.append(f"{what} (on no hole found)")
        return
    missing = [d for d in labels if d not in datums]
    if missing:
        holes_on = ", ".join(h.id for h in on)
        pmi.unmodelled.append(f"{what} on {holes_on} (datums {missing} not modelled)")
        return
    mod = obj.GetMaterialRequirementModifier()
    condition = "MMC" if mod == MOD_M else "LMC" if mod == MOD_L else "RFS"
    for h in on:
        pmi.tolerances.setdefault(h.id, {})["position"] = {
            "zone_diameter_m": value_mm * MM_TO_M,
            "datums": labels,
            "material_condition": condition,
            "pmi_id": name,
        }


def _dimension(lab, geo: _Faces, holes, pmi: Pmi) -> None:
    obj = _attr(lab, XCAFDoc_Dimension).GetObject()
    name = _name(obj) or "dimension"
    kind = str(obj.GetType()).split("DimensionType_", 1)[-1]
    on = _holes_of(geo.of(lab), holes)
    if obj.GetType() != SIZE_DIAMETER:
        pmi.unmodelled.append(f"{name}: {kind} {obj.GetValue():g} (not modelled)")
        return
    nominal_m = obj.GetValue() * MM_TO_M
    if obj.IsDimWithRange():
        upper = obj.GetUpperBound() * MM_TO_M - nominal_m
        lower = obj.GetLowerBound() * MM_TO_M - nominal_m
    elif obj.IsDimWithPlusMinusTolerance():
        upper = obj.GetUpperTolValue() * MM_TO_M
        lower = -abs(obj.GetLowerTolValue()) * MM_TO_M
    else:
        pmi.unmodelled.append(f"{name}: diameter {obj.GetValue():g} mm without limits")
        return
    what = f"{name}: diameter {obj.GetValue():g} mm {upper * 1e3:+g}/{lower * 1e3:+g}"
    if not on:
        pmi.unmodelled.append(f"{what} (on no hole found)")
        return
    for h in on:
        if abs(h.diameter_m - nominal_m) > SAME_SIZE_M:
            pmi.unmodelled.append(
                f"{what} on {h.id}: another bore than the measured one ({h.diameter_m * 1e3:g} mm)"
            )
            continue
        pmi.tolerances.setdefault(h.id, {})["size"] = {
            "upper_m": upper,
            "lower_m": lower,
            "pmi_id": name,
        }
