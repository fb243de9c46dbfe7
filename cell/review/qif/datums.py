"""QIF ``DatumDefinitions``, ``DatumReferenceFrames`` and the actual DRF transforms.

A datum of kind ``hole`` refers to its hole's circle feature, ``pattern`` to every hole of the
pattern, ``plane`` to a plane feature through its holes' nominal centres
(:func:`cell.review.qif.features.plane_through`); a plane given by points and an RPS datum
carry their label only (their geometry lives in the cell file, not in report.json).
Datum features of size are referenced ``REGARDLESS`` (RMB), planes and RPS ``NONE``.

The actual DRF is written as a QIF transform with "before" = DRF coordinates and "after" =
nominal part frame coordinates, i.e. the matrix of report.json's ``T_part_drf``
(``XDirection`` .. ``ZDirection`` are its rotation's columns, ``Origin`` its translation in m).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
from lxml import etree
from scipy.spatial.transform import Rotation

from cell.review.qif.errors import QifError
from cell.review.qif.features import FeatureIds, HoleNominal, plane_feature, plane_through
from cell.review.qif.xmlutil import Ids, counted, ids_list, sub, vec

PRECEDENCE = ("PRIMARY", "SECONDARY", "TERTIARY", "QUATERNARY", "QUINARY", "SENARY")


def pose_matrix(pose: Mapping[str, Any], what: str) -> np.ndarray:
    """A 4x4 from a pose ``{xyz, quat_xyzw}`` or ``{xyz, rpy}`` (m, rad)."""
    try:
        xyz = np.asarray(pose["xyz"], float).reshape(3)
        if "quat_xyzw" in pose:
            R = Rotation.from_quat(np.asarray(pose["quat_xyzw"], float).reshape(4)).as_matrix()
        else:
            R = Rotation.from_euler("xyz", np.asarray(pose["rpy"], float).reshape(3)).as_matrix()
    except (KeyError, TypeError, ValueError) as exc:
        raise QifError("report", [f"{what}: not a pose {{xyz, quat_xyzw}} ({exc})"]) from None
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = R, xyz
    return T


def datum_definitions(
    root: etree._Element,
    datums: Sequence[Mapping[str, Any]],
    holes: Mapping[str, HoleNominal],
    features: Mapping[str, FeatureIds],
    feature_lists: tuple[etree._Element, ...],
    ids: Ids,
) -> dict[str, int]:
    """``<DatumDefinitions>``; returns datum label -> its QIF id."""
    defs = counted(root, "DatumDefinitions")
    out: dict[str, int] = {}
    for d in datums:
        label, kind, names = d["label"], d["kind"], list(d.get("holes") or [])
        unknown = [n for n in names if n not in features]
        if unknown:
            raise QifError("report", [f"datum {label}: unknown hole(s) {unknown}"])
        if kind in ("hole", "pattern"):
            nominal_ids = [features[n].nominal for n in names]
        elif kind == "plane" and names:
            point, normal = plane_through([holes[n] for n in names])
            f = plane_feature(*feature_lists, f"datum {label}", point, normal, ids)
            nominal_ids = [f.nominal]
        else:
            nominal_ids = []
        out[label] = ids.next()
        e = sub(defs, "DatumDefinition", id=str(out[label]))
        sub(e, "DatumLabel", label)
        if nominal_ids:
            ids_list(e, "FeatureNominalIds", nominal_ids)
    return out


def reference_frames(
    root: etree._Element,
    frames: Sequence[Mapping[str, Any]],
    datums: Sequence[Mapping[str, Any]],
    datum_ids: Mapping[str, int],
    ids: Ids,
) -> dict[str, int]:
    """``<DatumReferenceFrames>``; returns DRF name -> its QIF id. A frame without datums (a
    best-fit alignment, ``ALIGN``) is no DRF: it gets no entry here, only its transform."""
    kind = {d["label"]: d["kind"] for d in datums}
    drfs = counted(root, "DatumReferenceFrames")
    out: dict[str, int] = {}
    for fr in frames:
        labels = list(fr.get("datums") or [])
        if not labels:
            continue
        missing = [lab for lab in labels if lab not in datum_ids]
        if missing or len(labels) > len(PRECEDENCE):
            raise QifError("report", [f"DRF {fr['id']}: datums {labels} (unknown: {missing})"])
        out[fr["id"]] = ids.next()
        e = sub(drfs, "DatumReferenceFrame", id=str(out[fr["id"]]))
        lst = counted(e, "Datums")
        for lab, prec in zip(labels, PRECEDENCE, strict=False):
            datum = sub(lst, "Datum")
            simple = sub(datum, "SimpleDatum")
            sub(simple, "DatumDefinitionId", str(datum_ids[lab]))
            size = kind[lab] in ("hole", "pattern")
            sub(simple, "MaterialModifier", "REGARDLESS" if size else "NONE")
            sub(simple, "ReferencedComponent", "ACTUAL")
            sub(sub(datum, "Precedence"), "PrecedenceEnum", prec)
    return out


def _transform(parent: etree._Element, T: np.ndarray, name: str, ids: Ids) -> int:
    tid = ids.next()
    t = sub(parent, "Transform", id=str(tid))
    rot = sub(t, "Rotation")
    for axis, col in zip(("XDirection", "YDirection", "ZDirection"), T[:3, :3].T, strict=True):
        sub(rot, axis, vec(col))
    sub(t, "Origin", vec(T[:3, 3]))
    sub(t, "Name", name)
    return tid


def actual_transforms(
    lst: etree._Element,
    top: etree._Element,
    frames: Sequence[Mapping[str, Any]],
    placement: Mapping[str, Any] | None,
    ids: Ids,
) -> dict[str, int]:
    """Fill ``<ActualTransforms>`` ``lst`` of the results: ``T_part_drf`` of every evaluated
    frame (named ``<id> T_part_drf``; a best fit's too) and the part's placement
    ``T_fixture_part``.

    The schema's key for ``DRFTransformActualId`` collects only the document's top-level
    ``<Transforms>``, so each DRF's transform is also written there (``top``, its own id, same
    name and matrix); returns DRF name -> that id, for the characteristic measurements (a best
    fit is no DRF and is not referenced)."""
    out: dict[str, int] = {}
    for fr in frames:
        if fr.get("status") == "evaluated" and fr.get("T_part_drf"):
            T = pose_matrix(fr["T_part_drf"], f"DRF {fr['id']} T_part_drf")
            _transform(lst, T, f"{fr['id']} T_part_drf", ids)
            if fr.get("datums"):
                out[fr["id"]] = _transform(top, T, f"{fr['id']} T_part_drf", ids)
    if placement and placement.get("T_fixture_part"):
        T = pose_matrix(placement["T_fixture_part"], "placement T_fixture_part")
        _transform(lst, T, "placement T_fixture_part", ids)
    return out
