"""Position and size tolerances of the XCAF document, matched to the holes' bores.

A position tolerance is kept on a hole (``tolerances.position``) when it is attached to the
walls of the bore the cell measures (the entry bore), its zone is a diameter (⌀), it has no
zone modifier (projected, free state, statistical...) nor maximum value (``|⌀.045 MAX|``, read
from the file's text: XCAF drops it) and its datum references are single datums without
modifiers; the datum letters in the order of the frame, the zone in metres and
the material condition (M: MMC, L: LMC, none: RFS) as the file gives them. A second position
tolerance on one hole (a composite or two stacked frames) is listed: the cell holds one.

A diameter dimension with limits is kept as ``tolerances.size`` of the hole whose measured
bore its faces are walls of, as the limits the drawing states (nominal plus deviations),
written about the model's diameter when the model was drawn at another size than the nominal
(NIST FTC-08 models its 6.0452 +0.127/-0.0254 holes at 6.0325: limits 6.0198..6.1722 kept).
OpenCascade gives a plus/minus dimension's lower deviation as a magnitude; it is taken as below
the nominal.
"""

from __future__ import annotations

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
from OCP.XCAFDimTolObjects import (
    XCAFDimTolObjects_GeomToleranceTypeValue_Diameter as ZONE_DIAMETER,
)
from OCP.XCAFDimTolObjects import (
    XCAFDimTolObjects_GeomToleranceZoneModif_None as NO_ZONE_MODIFIER,
)
from OCP.XCAFDoc import XCAFDoc_Datum, XCAFDoc_Dimension, XCAFDoc_DimTolTool, XCAFDoc_GeomTolerance

from cell.cad.holes import CadHole
from cell.cad.pmi_doc import Pmi, PmiFaces, attr, holes_of, labels, semantic_name
from cell.cad.step_read import MM_TO_M

#: a PMI names the measured bore when the diameters agree within this (m)
SAME_SIZE_M = 1e-6


def _enum(value) -> str:
    """``XCAFDimTolObjects_GeomToleranceType_Position`` -> ``Position``."""
    return str(value).split(".")[-1].rsplit("Type_", 1)[-1].rsplit("Modif_", 1)[-1]


def _datum_refs(lab) -> tuple[list[str], list[str]]:
    """The datum letters of a tolerance in the order of its frame, and what is not modelled
    of them (compound datums such as A-B, datum modifiers such as B at MMB)."""
    refs: dict[int, list[str]] = {}
    problems: list[str] = []
    for d_lab in labels(lambda s: XCAFDoc_DimTolTool.GetDatumWithObjectOfTolerLabels_s(lab, s)):
        d = attr(d_lab, XCAFDoc_Datum).GetObject()
        name = d.GetName().ToCString()
        refs.setdefault(d.GetPosition(), []).append(name)
        mods = d.GetModifiers()
        if mods.Length():
            kinds = sorted({_enum(mods.Value(i + 1)) for i in range(mods.Length())})
            problems.append(f"datum {name} with modifier {', '.join(kinds)}")
    out = []
    for pos in sorted(refs):
        names = refs[pos]
        if len(set(names)) > 1:
            problems.append(f"compound datum {'-'.join(names)}")
        out.append(names[0] if len(set(names)) == 1 else "-".join(names))
    return out, problems


def _zone_problem(obj) -> str:
    """Why the tolerance's zone is not a plain cylinder the cell checks ('' when it is)."""
    if obj.GetTypeOfValue() != ZONE_DIAMETER:
        return "its zone has no ⌀ (a width between planes, not a cylinder about the axis)"
    mods = obj.GetModifiers()
    named = [_enum(mods.Value(i + 1)) for i in range(mods.Length())]
    if obj.GetZoneModifier() != NO_ZONE_MODIFIER:
        named.append(_enum(obj.GetZoneModifier()))
    return f"zone modifiers {', '.join(named)} not modelled" if named else ""


def tolerance(lab, geo: PmiFaces, holes: list[CadHole], pmi: Pmi, capped: set[str]) -> None:
    """One geometric tolerance: kept on its holes, or listed (module doc). ``capped``: the
    names of the file's tolerances with a maximum value (read from its text)."""
    obj = attr(lab, XCAFDoc_GeomTolerance).GetObject()
    name = semantic_name(obj) or "geometric tolerance"
    value_mm = obj.GetValue()
    refs, ref_problems = _datum_refs(lab)
    what = f"{name}: {_enum(obj.GetType())} {value_mm:g} mm" + (
        f" |{'|'.join(refs)}" if refs else ""
    )
    if obj.GetType() != POSITION:
        pmi.unmodelled.append(f"{what} (not modelled: the cell evaluates position and size)")
        return
    faces = geo.of(lab)
    on = _holes_or_listed(pmi, what, faces, holes)
    if not on:
        return
    holes_on = ", ".join(h.id for h in on)
    why = _zone_problem(obj) or "; ".join(ref_problems)
    if not why and (obj.GetMaxValueModifier() > 0 or name in capped):
        why = "a maximum tolerance (MAX) not modelled"
    if why:
        pmi.unmodelled.append(f"{what} on {holes_on} ({why})")
        return
    mod = obj.GetMaterialRequirementModifier()
    condition = "MMC" if mod == MOD_M else "LMC" if mod == MOD_L else "RFS"
    for h in on:
        if _on_another_bore(pmi, geo, what, h, faces):
            continue
        held = pmi.tolerances.setdefault(h.id, {})
        if "position" in held:
            pmi.unmodelled.append(
                f"{what} on {h.id}: a second position tolerance (composite or stacked "
                f"frames; {held['position']['pmi_id']} kept)"
            )
            continue
        held["position"] = {
            "zone_diameter_m": round(value_mm * MM_TO_M, 12),  # to 1 pm: no inch residue
            "datums": refs,
            "material_condition": condition,
            "pmi_id": name,
        }


def _limits_mm(obj) -> tuple[float, float] | None:
    """The upper and lower limits of a dimension (mm), None when it states none."""
    nominal = obj.GetValue()
    if obj.IsDimWithRange():
        return obj.GetUpperBound(), obj.GetLowerBound()
    if obj.IsDimWithPlusMinusTolerance():
        return nominal + obj.GetUpperTolValue(), nominal - abs(obj.GetLowerTolValue())
    return None


def dimension(lab, geo: PmiFaces, holes: list[CadHole], pmi: Pmi) -> None:
    """One dimension: a hole's size tolerance, or listed (module doc)."""
    obj = attr(lab, XCAFDoc_Dimension).GetObject()
    name = semantic_name(obj) or "dimension"
    if obj.GetType() != SIZE_DIAMETER:
        kind = str(obj.GetType()).split("DimensionType_", 1)[-1]
        pmi.unmodelled.append(f"{name}: {kind} {obj.GetValue():g} (not modelled)")
        return
    limits = _limits_mm(obj)
    nominal_mm = obj.GetValue()
    if limits is None:
        pmi.unmodelled.append(f"{name}: diameter {nominal_mm:g} mm without limits")
        return
    upper_mm, lower_mm = limits
    what = (
        f"{name}: diameter {nominal_mm:g} mm {upper_mm - nominal_mm:+.6g}/"
        f"{lower_mm - nominal_mm:+.6g}"
    )
    faces = geo.of(lab)
    on = _holes_or_listed(pmi, what, faces, holes)
    if not on:
        return
    for h in on:
        if _on_another_bore(pmi, geo, what, h, faces):
            continue
        drawn_at_nominal = abs(nominal_mm * MM_TO_M - h.diameter_m) <= SAME_SIZE_M
        if not drawn_at_nominal:
            pmi.notes.append(
                f"{what} on {h.id}: the model's bore is {h.diameter_m * 1e3:g} mm; the limits "
                f"{lower_mm:g}..{upper_mm:g} mm are kept about it"
            )
        held = pmi.tolerances.setdefault(h.id, {})
        if "size" in held:
            pmi.unmodelled.append(
                f"{what} on {h.id}: a second size ({held['size']['pmi_id']} kept)"
            )
            continue
        # about the nominal as drawn, or about the model's diameter when it differs (to 1 pm)
        base_mm = nominal_mm if drawn_at_nominal else h.diameter_m / MM_TO_M
        held["size"] = {
            "upper_m": round((upper_mm - base_mm) * MM_TO_M, 12),
            "lower_m": round((lower_mm - base_mm) * MM_TO_M, 12),
            "pmi_id": name,
        }


def _on_another_bore(pmi, geo, what: str, h, faces) -> bool:
    """Whether ``what`` sits on a bore of hole ``h`` other than the entry bore the cell
    measures (a counterbore's through bore); if so it is listed in ``pmi.unmodelled``."""
    bore = geo.bore_of(h, faces)
    if bore is None or abs(bore - h.diameter_m) <= SAME_SIZE_M:
        return False
    pmi.unmodelled.append(
        f"{what} on {h.id}: on its {bore * 1e3:g} mm bore, the cell measures the "
        f"{h.diameter_m * 1e3:g} mm entry bore"
    )
    return True


def _holes_or_listed(pmi, what: str, faces, holes):
    """The holes whose walls ``faces`` are; none: ``what`` is listed in ``pmi.unmodelled``
    with where it sits instead."""
    on = holes_of(faces, holes)
    if not on:
        where = f"on {len(faces)} faces, none a hole's wall" if faces else "attached to no face"
        pmi.unmodelled.append(f"{what} ({where})")
    return on
