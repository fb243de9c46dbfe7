"""QIF ``Characteristics`` (definitions, nominals, items) and ``CharacteristicMeasurements``.

One definition, nominal and item per report characteristic (``kind`` ``diameter`` or
``position``), the item named by the characteristic's id (``H3.position``) and pointing at its
hole's circle feature item.

- Diameter: ``Tolerance`` ``MaxValue`` / ``MinValue`` = report.json's ``upper_m`` / ``lower_m``
  with ``DefinedAsLimit`` false (deviations from the nominal, as the drawing writes them);
  ``TargetValue`` = ``nominal_m``.
- Position: ``ToleranceValue`` = ``zone_diameter_m``, a ``DiametricalZone``, the DRF, the
  material condition (RFS -> REGARDLESS, MMC -> MAXIMUM, LMC -> LEAST) and, at MMC/LMC, the
  hole's diameter characteristic as ``SizeCharacteristicDefinitionId``.
- Measurements: ``Value`` = ``value_m`` with ``combinedUncertainty`` = ``U_m`` / 2 (the
  report's U is expanded with k = 2, or the 95 % Monte Carlo interval for position; QIF's
  combined uncertainty is a standard one) and ``meanError`` 0 (known errors are corrected);
  the exact ``U_m`` rides along as the user attribute ``U_m`` and a non-empty ``reason`` as
  the attribute ``reason``; ``Bonus`` at MMC/LMC;
  ``DRFTransformActualId``; ``Status`` from the decision (:data:`STATUS`).
"""

from __future__ import annotations

from collections.abc import Collection, Mapping, Sequence
from typing import Any

from lxml import etree

from cell.review.qif.errors import QifError
from cell.review.qif.features import FeatureIds
from cell.review.qif.xmlutil import Ids, counted, dec, ids_list, sub

#: report decision -> QIF CharacteristicStatusEnum
STATUS = {
    "conformance": "PASS",
    "nonconformance": "FAIL",
    "inconclusive": "INDETERMINATE",
    "not_evaluated": "NOT_ANALYZED",
}
MATERIAL = {"RFS": "REGARDLESS", "MMC": "MAXIMUM", "LMC": "LEAST"}
KINDS = {"diameter": "Diameter", "position": "Position"}


def _kind(c: Mapping[str, Any]) -> str:
    if c.get("kind") not in KINDS:
        raise QifError(
            "report",
            [
                f"characteristic {c.get('id')!r}: kind {c.get('kind')!r} "
                f"is not one of {sorted(KINDS)}"
            ],
        )
    return KINDS[c["kind"]]


def characteristic_section(
    root: etree._Element,
    chars: Sequence[Mapping[str, Any]],
    features: Mapping[str, FeatureIds],
    drf_ids: Mapping[str, int],
    standard_id: int,
    ids: Ids,
    other_frames: Collection[str] = ("fixture",),
) -> dict[str, tuple[int, int]]:
    """``<Characteristics>`` (under the standard ``standard_id``); returns characteristic id ->
    (definition id, item id); nothing without characteristics."""
    if not chars:
        return {}
    sec = sub(root, "Characteristics")
    sub(sec, "FormalStandardId", str(standard_id))
    defs = counted(sec, "CharacteristicDefinitions")
    noms = counted(sec, "CharacteristicNominals")
    items = counted(sec, "CharacteristicItems")
    out: dict[str, tuple[int, int]] = {}
    size_def: dict[str, int] = {}
    for c in sorted(chars, key=lambda c: c["kind"] != "diameter"):  # sizes first: MMC refers
        name, k = c["id"], _kind(c)
        if c["hole_id"] not in features:
            raise QifError("report", [f"characteristic {name}: unknown hole {c['hole_id']!r}"])
        d_id, n_id, i_id = ids.next(), ids.next(), ids.next()
        d = sub(defs, f"{k}CharacteristicDefinition", id=str(d_id))
        if k == "Diameter":
            size_def[c["hole_id"]] = d_id
            tol = sub(d, "Tolerance")
            sub(tol, "MaxValue", dec(c["upper_m"]))
            sub(tol, "MinValue", dec(c["lower_m"]))
            sub(tol, "DefinedAsLimit", "false")
        else:
            _position_definition(d, c, drf_ids, size_def, other_frames)
        n = sub(noms, f"{k}CharacteristicNominal", id=str(n_id))
        sub(n, "CharacteristicDefinitionId", str(d_id))
        sub(n, "Name", name)
        if k == "Diameter":
            sub(n, "TargetValue", dec(c["nominal_m"]))
        it = sub(items, f"{k}CharacteristicItem", id=str(i_id))
        if c.get("pmi_id"):  # the drawing's name of the characteristic (AP242 PMI)
            sub(counted(it, "Attributes"), "AttributeStr", name="pmi_id", value=str(c["pmi_id"]))
        sub(it, "Name", name)
        ids_list(it, "FeatureItemIds", [features[c["hole_id"]].item])
        sub(it, "CharacteristicNominalId", str(n_id))
        out[name] = (d_id, i_id)
    return out


def _position_definition(
    d: etree._Element,
    c: Mapping[str, Any],
    drf_ids: Mapping[str, int],
    size_def: Mapping[str, int],
    other_frames: Collection[str],
) -> None:
    """A position definition; evaluated in a frame that is no DRF (``fixture``: the nominal
    part frame; a best fit) it carries no ``DatumReferenceFrameId``."""
    sub(d, "ToleranceValue", dec(c["zone_diameter_m"]))
    drf = c.get("drf")
    if drf is not None and drf not in other_frames:
        if drf not in drf_ids:
            raise QifError("report", [f"characteristic {c['id']}: unknown DRF {drf!r}"])
        sub(d, "DatumReferenceFrameId", str(drf_ids[drf]))
    mc = c.get("material_condition") or "RFS"
    if mc not in MATERIAL:
        raise QifError("report", [f"characteristic {c['id']}: material_condition {mc!r}"])
    sub(d, "MaterialCondition", MATERIAL[mc])
    if mc != "RFS" and c["hole_id"] in size_def:
        sub(d, "SizeCharacteristicDefinitionId", str(size_def[c["hole_id"]]))
    sub(sub(d, "ZoneShape"), "DiametricalZone")


def _value(parent: etree._Element, tag: str, v: float, U: float | None) -> None:
    e = sub(parent, tag, dec(v))
    if U is not None:
        e.set("combinedUncertainty", dec(U / 2.0))
        e.set("meanError", "0")


def characteristic_measurements(
    mc: etree._Element,
    chars: Sequence[Mapping[str, Any]],
    item_ids: Mapping[str, tuple[int, int]],
    features: Mapping[str, FeatureIds],
    transform_ids: Mapping[str, int],
    ids: Ids,
    timestamp: str | None = None,
) -> None:
    """Fill ``<CharacteristicMeasurements>`` ``mc``: one measurement per characteristic
    (``timestamp``: the run's start as ``xs:dateTime``, UTC)."""
    for c in chars:
        k, decision = _kind(c), c.get("decision")
        if decision not in STATUS:
            raise QifError(
                "report",
                [f"characteristic {c['id']}: decision {decision!r} is not one of {sorted(STATUS)}"],
            )
        m = sub(mc, f"{k}CharacteristicMeasurement", id=str(ids.next()))
        evaluated = decision != "not_evaluated" and c.get("value_m") is not None
        reason = " ".join(str(c.get("reason") or "").split())
        if (evaluated and c.get("U_m") is not None) or reason:
            attrs = counted(m, "Attributes")
            if evaluated and c.get("U_m") is not None:
                sub(attrs, "AttributeD1", name="U_m", value=dec(c["U_m"]))
            if reason:
                sub(attrs, "AttributeStr", name="reason", value=reason)
        sub(sub(m, "Status"), "CharacteristicStatusEnum", STATUS[decision])
        sub(m, "CharacteristicItemId", str(item_ids[c["id"]][1]))
        if timestamp:
            sub(m, "TimeStamp", timestamp)
        fm = features[c["hole_id"]].measurement
        if fm:
            ids_list(m, "FeatureMeasurementIds", [fm])
        if not evaluated:
            continue
        _value(m, "Value", c["value_m"], c.get("U_m"))
        if k == "Position":
            if (c.get("material_condition") or "RFS") != "RFS" and c.get("bonus_m") is not None:
                _value(m, "Bonus", c["bonus_m"], None)
            if c.get("drf") in transform_ids:
                sub(m, "DRFTransformActualId", str(transform_ids[c["drf"]]))
