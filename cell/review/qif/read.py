"""Read a ``report.qif`` back: its characteristics (tolerance, value, uncertainty, status),
measured features and actual transforms, after validating it against the QIF schemas.

Interpreted: circle features, diameter and position characteristics, actual transforms and the
inspection status; other QIF content is validated but not read. Lengths are returned in m,
converted from the file's ``FileUnits`` linear unit (``UnitConversion/Factor``, as in the
community samples written in mm; the schema admits metre-based units only).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from lxml import etree

from cell.review.qif.errors import QifError
from cell.review.qif.validator import NS, validate_file

_NS = {"q": NS}
MATERIAL_BACK = {"REGARDLESS": "RFS", "MAXIMUM": "MMC", "LEAST": "LMC"}


@dataclass(frozen=True)
class CharacteristicResult:
    """One characteristic of a QIF results file (m). ``lower_m`` / ``upper_m``: the diameter's
    limits as deviations from ``nominal_m`` (None when a file gives absolute limits without a
    nominal), ``lsl_m`` / ``usl_m`` the absolute limits; ``zone_m``: the position zone
    diameter."""

    name: str
    kind: str
    status: str
    value_m: float | None
    U_m: float | None
    combined_uncertainty_m: float | None
    nominal_m: float | None = None
    lower_m: float | None = None
    upper_m: float | None = None
    lsl_m: float | None = None
    usl_m: float | None = None
    zone_m: float | None = None
    bonus_m: float | None = None
    material_condition: str | None = None
    drf_transform: str | None = None
    reason: str = ""


@dataclass(frozen=True)
class QifResults:
    """What a report.qif holds for statistics and checks."""

    path: str
    qpid: str
    timestamp: str | None
    inspection_status: str
    characteristics: list[CharacteristicResult]
    #: hole id -> (centre m, diameter m, axis or None), part frame
    features: dict[str, tuple[np.ndarray, float | None, np.ndarray | None]] = field(
        default_factory=dict
    )
    #: transform name -> 4x4 (``T_after_before``)
    transforms: dict[str, np.ndarray] = field(default_factory=dict)


def _f(e: etree._Element | None, k: float = 1.0) -> float | None:
    return None if e is None or e.text is None else float(e.text) * k


def _vec(e: etree._Element | None, k: float = 1.0) -> np.ndarray | None:
    return None if e is None else np.array([float(v) * k for v in e.text.split()])


def length_factor(root: etree._Element) -> float:
    """Metres per length unit of the file (its ``LinearUnit``'s ``UnitConversion/Factor``; the
    schema fixes the ``SIUnitName`` to meter; 1 when the file declares no factor)."""
    factor = root.findtext("q:FileUnits/q:PrimaryUnits/q:LinearUnit/q:UnitConversion/q:Factor",
                           None, _NS)  # fmt: skip
    return 1.0 if factor is None else float(factor)


def _by_id(root: etree._Element) -> dict[str, etree._Element]:
    return {e.get("id"): e for e in root.iter() if isinstance(e.tag, str) and e.get("id")}


def _transforms(root: etree._Element, k: float) -> dict[str, np.ndarray]:
    out = {}
    for t in root.iterfind(".//q:ActualTransforms/q:Transform", _NS):
        T = np.eye(4)
        for j, axis in enumerate(("XDirection", "YDirection", "ZDirection")):
            T[:3, j] = _vec(t.find(f"q:Rotation/q:{axis}", _NS))
        T[:3, 3] = _vec(t.find("q:Origin", _NS), k)
        out[t.findtext("q:Name", "", _NS)] = T
    return out


def _features(root: etree._Element, ids: dict[str, etree._Element], k: float) -> dict:
    out = {}
    for m in root.iterfind(".//q:MeasuredFeatures/q:CircleFeatureMeasurement", _NS):
        item = ids[m.findtext("q:FeatureItemId", None, _NS)]
        out[item.findtext("q:FeatureName", "", _NS)] = (
            _vec(m.find("q:Location", _NS), k),
            _f(m.find("q:Diameter", _NS), k),
            _vec(m.find("q:Normal", _NS)),
        )
    return out


def _attr(m: etree._Element, name: str) -> str | None:
    for a in m.iterfind("q:Attributes/*", _NS):
        if a.get("name") == name:
            return a.get("value")
    return None


def _characteristic(
    m: etree._Element, ids: dict[str, etree._Element], k: float
) -> CharacteristicResult:
    kind = etree.QName(m).localname.removesuffix("CharacteristicMeasurement").lower()
    item = ids[m.findtext("q:CharacteristicItemId", None, _NS)]
    nominal = ids[item.findtext("q:CharacteristicNominalId", None, _NS)]
    definition = ids[nominal.findtext("q:CharacteristicDefinitionId", None, _NS)]
    value = m.find("q:Value", _NS)
    U = _attr(m, "U_m")
    cu = (
        None
        if value is None or value.get("combinedUncertainty") is None
        else float(value.get("combinedUncertainty")) * k
    )
    tid = m.findtext("q:DRFTransformActualId", None, _NS)
    common = dict(
        name=item.findtext("q:Name", "", _NS),
        kind=kind,
        status=m.findtext("q:Status/q:CharacteristicStatusEnum", "", _NS),
        value_m=_f(value, k),
        U_m=None if U is None else float(U) * k,
        combined_uncertainty_m=cu,
        reason=_attr(m, "reason") or "",
        drf_transform=None if tid is None else ids[tid].findtext("q:Name", "", _NS),
    )
    if kind == "diameter":
        return _diameter(common, nominal, definition, k)
    mc = definition.findtext("q:MaterialCondition", None, _NS)
    return CharacteristicResult(
        **common,
        zone_m=_f(definition.find("q:ToleranceValue", _NS), k),
        usl_m=_f(definition.find("q:ToleranceValue", _NS), k),
        bonus_m=_f(m.find("q:Bonus", _NS), k),
        material_condition=MATERIAL_BACK.get(mc, mc),
    )


def _diameter(common: dict, nominal: etree._Element, definition: etree._Element,
              k: float) -> CharacteristicResult:  # fmt: skip
    target = _f(nominal.find("q:TargetValue", _NS), k)
    lo = _f(definition.find("q:Tolerance/q:MinValue", _NS), k)
    hi = _f(definition.find("q:Tolerance/q:MaxValue", _NS), k)
    if definition.findtext("q:Tolerance/q:DefinedAsLimit", "false", _NS).strip() == "true":
        dev = (None, None) if target is None else (lo - target, hi - target)
        return CharacteristicResult(**common, nominal_m=target, lower_m=dev[0], upper_m=dev[1],
                                    lsl_m=lo, usl_m=hi)  # fmt: skip
    lsl, usl = (None, None) if target is None else (target + lo, target + hi)
    return CharacteristicResult(**common, nominal_m=target, lower_m=lo, upper_m=hi, lsl_m=lsl,
                                usl_m=usl)  # fmt: skip


def read_qif(path: str | Path) -> QifResults:
    """Validate and read ``path`` (raises :class:`QifError` naming the file)."""
    tree = validate_file(path)
    root = tree.getroot()
    ids = _by_id(root)
    results = root.findall(".//q:Results/q:MeasurementResultsSet/q:MeasurementResults", _NS)
    if len(results) != 1:
        raise QifError(str(path), [f"{len(results)} MeasurementResults (a run writes one)"])
    mr = results[0]
    k = length_factor(root)
    chars = [
        _characteristic(m, ids, k)
        for m in mr.iterfind("q:MeasuredCharacteristics/q:CharacteristicMeasurements/*", _NS)
        if etree.QName(m).localname
        in ("DiameterCharacteristicMeasurement", "PositionCharacteristicMeasurement")
    ]
    return QifResults(
        path=str(path),
        qpid=root.findtext("q:QPId", "", _NS),
        timestamp=mr.findtext(".//q:TimeStamp", None, _NS),
        inspection_status=mr.findtext("q:InspectionStatus/q:InspectionStatusEnum", "", _NS),
        characteristics=chars,
        features=_features(mr, ids, k),
        transforms=_transforms(mr, k),
    )
