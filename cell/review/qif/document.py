"""One run's ``report.qif``: a QIF 3.0 ``QIFDocument`` built from a report.json mapping.

Sections, in the schema's order: ``QPId`` (a UUID derived from the cell's SHA-256 and the
run's start time, so writing the same run again gives the same id), ``Header``, ``FileUnits``
(SI: metre, radian), ``StandardsDefinitions`` (ISO 1101), ``DatumDefinitions``,
``Transforms`` (the actual DRF transforms, see :func:`.datums.actual_transforms`),
``DatumReferenceFrames``, ``Features``,
``Characteristics`` and ``Results`` (one ``MeasurementResults``: ``MeasuredFeatures``,
``MeasuredCharacteristics``, ``ActualTransforms``, ``InspectionStatus``). Every written
document is validated against the vendored QIF 3.0 schemas before it is stored.

``InspectionStatus``: FAIL if any characteristic is FAIL, else UNKNOWN if any is inconclusive
or not evaluated (QIF's inspection status has no INDETERMINATE), else PASS; a report without
characteristics (no drawing tolerances evaluated) is NOT_CALCULATED.
"""

from __future__ import annotations

import uuid
from collections.abc import Mapping, Sequence
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

from lxml import etree

from cell.review.qif.characteristics import characteristic_measurements, characteristic_section
from cell.review.qif.datums import actual_transforms, datum_definitions, reference_frames
from cell.review.qif.errors import QifError
from cell.review.qif.features import (
    HoleNominal,
    features_section,
    hole_features,
    measured_features,
)
from cell.review.qif.validator import NS, validate_tree
from cell.review.qif.xmlutil import Ids, counted, finish_counts, sub

QIF_VERSION = "3.0.0"
_QPID_NAMESPACE = uuid.uuid5(uuid.NAMESPACE_URL, "holecell:report.qif")


def inspection_status(chars: Sequence[Mapping[str, Any]]) -> str:
    """The run's QIF ``InspectionStatusEnum`` from its characteristics' decisions."""
    decisions = [c.get("decision") for c in chars]
    if not decisions:
        return "NOT_CALCULATED"
    if "nonconformance" in decisions:
        return "FAIL"
    if any(d != "conformance" for d in decisions):
        return "UNKNOWN"
    return "PASS"


def _header(root: etree._Element, report: Mapping[str, Any], ids: Ids) -> int:
    summ = report.get("summary") or {}
    sub(
        root,
        "QPId",
        str(uuid.uuid5(_QPID_NAMESPACE, f"{summ.get('cell_sha256')}/{summ.get('started_at')}")),
    )
    app = sub(sub(root, "Header"), "Application")
    sub(app, "Name", "holecell")
    sub(app, "Organization", "holecell")
    std_id = ids.next()
    std = sub(counted(root, "StandardsDefinitions"), "Standard", id=str(std_id))
    sub(sub(std, "Organization"), "StandardsOrganizationEnum", "ISO")
    sub(std, "Designator", "1101")
    sub(std, "Year", "2017")
    units = sub(sub(root, "FileUnits"), "PrimaryUnits")
    ang = sub(units, "AngularUnit")
    sub(ang, "SIUnitName", "radian")
    sub(ang, "UnitName", "rad")
    lin = sub(units, "LinearUnit")
    sub(lin, "SIUnitName", "meter")
    sub(lin, "UnitName", "m")
    return std_id


def _timestamp(report: Mapping[str, Any]) -> str | None:
    """The run's start (report.json ``summary.started_at``, s since the epoch) as UTC
    ``xs:dateTime``."""
    t = (report.get("summary") or {}).get("started_at")
    if t is None:
        return None
    return datetime.fromtimestamp(float(t), UTC).strftime("%Y-%m-%dT%H:%M:%S.%fZ")


def _prune(root: etree._Element) -> None:
    """Drop empty lists (and containers left empty) that the schema would refuse."""
    changed = True
    while changed:
        changed = False
        for e in list(root.iter()):
            empty = len(e) == 0 and not (e.text or "").strip() and e is not root
            if empty and (
                e.get("n") == "0"
                or etree.QName(e).localname
                in ("MeasuredCharacteristics", "Features", "Characteristics")
            ):
                e.getparent().remove(e)
                changed = True


def build_qif(
    report: Mapping[str, Any],
    nominals: Mapping[str, HoleNominal],
    measured_normals: Mapping[str, Sequence[float]] | None = None,
) -> etree._Element:
    """The ``QIFDocument`` of a report.json mapping (``holes`` plus, when present, ``datums``,
    ``datum_reference_frames``, ``placement`` and ``characteristics``). ``nominals``: hole id ->
    the cell file's hole (part frame), every hole of the part; ``measured_normals``: hole id ->
    measured axis (part frame), for the measured features."""
    ids = Ids()
    holes = list(report.get("holes") or [])
    datums = list(report.get("datums") or [])
    frames = list(report.get("datum_reference_frames") or [])
    chars = list(report.get("characteristics") or [])
    unknown = [h["hole_id"] for h in holes if h["hole_id"] not in nominals]
    if unknown:
        raise QifError("report", [f"hole {unknown[0]!r} is not in the run's cell file"])
    root = etree.Element(f"{{{NS}}}QIFDocument", nsmap={None: NS}, versionQIF=QIF_VERSION)
    std_id = _header(root, report, ids)
    # the Features section comes after the datums in the file but datums refer to features:
    # build features detached, then place every section in the schema's order
    feats_holder = etree.Element("holder")
    lists = features_section(feats_holder)
    features = hole_features(*lists, nominals, ids)
    datum_ids = datum_definitions(root, datums, nominals, features, lists, ids)
    top_transforms = counted(root, "Transforms")
    drf_ids = reference_frames(root, frames, datums, datum_ids, ids)
    root.append(feats_holder[0])
    other_frames = {"fixture"} | {fr["id"] for fr in frames if not fr.get("datums")}
    item_ids = characteristic_section(root, chars, features, drf_ids, std_id, ids, other_frames)
    mr = sub(
        counted(sub(root, "Results"), "MeasurementResultsSet"),
        "MeasurementResults",
        id=str(ids.next()),
    )
    mf = counted(mr, "MeasuredFeatures")
    mc = counted(sub(mr, "MeasuredCharacteristics"), "CharacteristicMeasurements")
    at = counted(mr, "ActualTransforms")
    measured_features(mf, holes, features, measured_normals or {}, ids)
    transform_ids = actual_transforms(at, top_transforms, frames, report.get("placement"), ids)
    characteristic_measurements(
        mc, chars, item_ids, features, transform_ids, ids, _timestamp(report)
    )
    sub(sub(mr, "InspectionStatus"), "InspectionStatusEnum", inspection_status(chars))
    _prune(root)
    finish_counts(root)
    root.set("idMax", str(ids.last))
    return root


def write_qif(
    report: Mapping[str, Any],
    path: str | Path,
    nominals: Mapping[str, HoleNominal],
    measured_normals: Mapping[str, Sequence[float]] | None = None,
) -> Path:
    """Build, validate (raises :class:`~cell.review.qif.errors.QifError`) and write
    ``report.qif`` to ``path`` (atomically: a reader never sees half a file)."""
    path = Path(path)
    root = build_qif(report, nominals, measured_normals)
    validate_tree(root, str(path))
    tmp = path.with_name(path.name + ".tmp")
    etree.ElementTree(root).write(
        str(tmp), xml_declaration=True, encoding="UTF-8", pretty_print=True
    )
    tmp.replace(path)
    return path
