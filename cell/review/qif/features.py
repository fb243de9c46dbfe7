"""QIF ``Features`` (one circle per hole, one plane per plane datum) and ``MeasuredFeatures``.

Every hole is a ``Circle`` feature: the stereo head measures the rim where the hole meets the
surface (its centre, its normal = the hole's axis, its diameter), which is what QIF's circle
carries (``Location``, ``Normal``, ``Diameter``). Every hole of the cell file is a feature
(nominal and item), measured or not; a measured hole also gets a feature measurement.
Nominals and measurements are in the nominal part frame (``part.base``), in metres. A plane
datum named by holes gets a ``Plane`` feature whose nominal is the least-squares plane through
those holes' nominal centres, its normal on the side of their nominal axes.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from lxml import etree

from cell.review.qif.errors import QifError
from cell.review.qif.xmlutil import Ids, counted, dec, sub, vec


@dataclass(frozen=True)
class HoleNominal:
    """A hole as the cell file gives it: centre (m) and unit axis in the part frame, diameter
    (m)."""

    position_m: Sequence[float]
    normal: Sequence[float]
    diameter_m: float


@dataclass
class FeatureIds:
    """The QIF ids of one feature: definition, nominal, item, measurement (0: none)."""

    definition: int
    nominal: int
    item: int
    measurement: int = 0


def measured_centre(hole: Mapping[str, Any]) -> list[float] | None:
    """A report row's measured centre (m, part frame); None when not measured."""
    if hole.get("measured_x_m") is None:
        return None
    return [float(hole[f"measured_{a}_m"]) for a in "xyz"]


def _unit(v: Sequence[float], what: str) -> np.ndarray:
    a = np.asarray(v, float).reshape(-1)
    n = float(np.linalg.norm(a)) if a.shape == (3,) else 0.0
    if not n > 0 or not np.isfinite(n):
        raise QifError("report", [f"{what}: not a non-zero 3-vector ({list(v)!r})"])
    return a / n


def plane_through(holes: Sequence[HoleNominal]) -> tuple[np.ndarray, np.ndarray]:
    """The least-squares plane through the holes' nominal centres: (point, unit normal), the
    normal on the side of the holes' mean nominal axis (for fewer than three holes: the point
    is their centroid and the normal their mean axis)."""
    pts = np.array([h.position_m for h in holes], float)
    mean_axis = _unit(
        np.sum([_unit(h.normal, "hole axis") for h in holes], 0), "mean axis of the plane's holes"
    )
    centroid = pts.mean(axis=0)
    if len(pts) < 3:
        return centroid, mean_axis
    _, s, vt = np.linalg.svd(pts - centroid)
    n = vt[2] if s[1] > 1e-9 else mean_axis
    return centroid, (n if n @ mean_axis >= 0 else -n)


def hole_features(
    definitions: etree._Element,
    nominals: etree._Element,
    items: etree._Element,
    holes: Mapping[str, HoleNominal],
    ids: Ids,
) -> dict[str, FeatureIds]:
    """A circle definition, nominal and item per hole of the cell file (internal, at the
    nominal diameter), measured or not."""
    out: dict[str, FeatureIds] = {}
    for hid, h in holes.items():
        f = FeatureIds(ids.next(), ids.next(), ids.next())
        d = sub(definitions, "CircleFeatureDefinition", id=str(f.definition))
        sub(d, "InternalExternal", "INTERNAL")
        sub(d, "Diameter", dec(h.diameter_m))
        n = sub(nominals, "CircleFeatureNominal", id=str(f.nominal))
        sub(n, "FeatureDefinitionId", str(f.definition))
        sub(n, "Location", vec(h.position_m))
        sub(n, "Normal", vec(_unit(h.normal, f"hole {hid!r} axis")))
        it = sub(items, "CircleFeatureItem", id=str(f.item))
        sub(it, "FeatureNominalId", str(f.nominal))
        sub(it, "FeatureName", hid)
        sub(sub(it, "DeterminationMode"), "Checked")
        out[hid] = f
    return out


def plane_feature(
    definitions: etree._Element,
    nominals: etree._Element,
    items: etree._Element,
    name: str,
    point: np.ndarray,
    normal: np.ndarray,
    ids: Ids,
) -> FeatureIds:
    """A plane definition, nominal (``point``, ``normal`` in the part frame) and item."""
    f = FeatureIds(ids.next(), ids.next(), ids.next())
    sub(definitions, "PlaneFeatureDefinition", id=str(f.definition))
    n = sub(nominals, "PlaneFeatureNominal", id=str(f.nominal))
    sub(n, "FeatureDefinitionId", str(f.definition))
    sub(n, "Location", vec(point))
    sub(n, "Normal", vec(normal))
    it = sub(items, "PlaneFeatureItem", id=str(f.item))
    sub(it, "FeatureNominalId", str(f.nominal))
    sub(it, "FeatureName", name)
    sub(sub(it, "DeterminationMode"), "Checked")
    return f


def features_section(root: etree._Element) -> tuple[etree._Element, ...]:
    """``<Features>`` with its three lists (definitions, nominals, items)."""
    feats = sub(root, "Features")
    return (
        counted(feats, "FeatureDefinitions"),
        counted(feats, "FeatureNominals"),
        counted(feats, "FeatureItems"),
    )


def measured_features(
    mf: etree._Element,
    holes: Sequence[Mapping[str, Any]],
    features: Mapping[str, FeatureIds],
    measured_normals: Mapping[str, Sequence[float]],
    ids: Ids,
) -> None:
    """Fill ``<MeasuredFeatures>`` ``mf``: a circle measurement per measured hole (centre with
    ``combinedUncertainty`` = U_position/4 (U_position is the U of the position's ⌀: the
    centre's expanded uncertainty is half of it, k = 2), the measured axis when known, diameter with
    ``combinedUncertainty`` = U_diameter/2; k = 2 is the report's coverage factor); in a
    referenced run an attribute ``located_by`` says by which markers the stop was located, or
    that it fell back to the arm."""
    for h in holes:
        centre = measured_centre(h)
        if centre is None:
            continue
        f = features[h["hole_id"]]
        f.measurement = ids.next()
        m = sub(mf, "CircleFeatureMeasurement", id=str(f.measurement))
        if h.get("referenced") is not None:  # a referenced run: located by markers, or the arm
            how = (f"markers {h.get('reference_markers') or ''}".strip() if h["referenced"]
                   else "the arm's kinematic chain (fewer than 4 usable markers)")  # fmt: skip
            sub(counted(m, "Attributes"), "AttributeStr", name="located_by", value=how)
        sub(m, "FeatureItemId", str(f.item))
        loc = sub(m, "Location", vec(centre))
        if h.get("U_position_m") is not None:
            loc.set("combinedUncertainty", dec(h["U_position_m"] / 4.0))
        if h["hole_id"] in measured_normals:
            sub(m, "Normal", vec(_unit(measured_normals[h["hole_id"]], f"{h['hole_id']} axis")))
        dia = sub(m, "Diameter", dec(h["diameter_m"]))
        if h.get("U_diameter_m") is not None:
            dia.set("combinedUncertainty", dec(h["U_diameter_m"] / 2.0))
            dia.set("meanError", "0")
