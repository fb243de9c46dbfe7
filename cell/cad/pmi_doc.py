"""The PMI of an XCAF document as :mod:`cell.cad.pmi` reads it: the result (:class:`Pmi`), the
attributes of its labels, and the faces a PMI label is attached to (:class:`PmiFaces`: face-map
numbers, with each face's plane or cylinder diameter for matching them to holes)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
from OCP.BRepAdaptor import BRepAdaptor_Surface
from OCP.GeomAbs import GeomAbs_Cylinder, GeomAbs_Plane
from OCP.OCP.collections import Sequence_TDF_Label
from OCP.TDF import TDF_AttributeIterator, TDF_Label
from OCP.TopAbs import TopAbs_FACE
from OCP.TopExp import TopExp_Explorer
from OCP.TopoDS import TopoDS
from OCP.XCAFDoc import XCAFDoc_DimTolTool, XCAFDoc_DocumentTool

from cell.cad.cylinders import face_map
from cell.cad.holes import CadHole
from cell.cad.step_read import MM_TO_M, StepDocument


@dataclass
class Pmi:
    """The PMI found: ``semantic`` False when the file has none; ``datums`` and per-hole
    ``tolerances`` as cell-file mappings; ``unmodelled`` one line per PMI left out; ``notes``
    how some of what was kept was read (the entity graph where XCAF had no faces)."""

    semantic: bool = False
    datums: list[dict[str, Any]] = field(default_factory=list)
    tolerances: dict[str, dict[str, Any]] = field(default_factory=dict)
    unmodelled: list[str] = field(default_factory=list)
    counts: dict[str, int] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)


def attr(label: TDF_Label, cls: type) -> Any:
    """The attribute of type ``cls`` on ``label`` (None: none)."""
    it = TDF_AttributeIterator(label)
    while it.More():
        if isinstance(it.Value(), cls):
            return it.Value()
        it.Next()
    return None


def labels(getter) -> list[TDF_Label]:
    """The labels a ``Get...Labels(sequence)`` method of XCAF fills in."""
    seq = Sequence_TDF_Label()
    getter(seq)
    return [seq.Value(i + 1) for i in range(seq.Length())]


def semantic_name(obj) -> str:
    """A PMI object's name in the file ('' when none)."""
    n = obj.GetSemanticName()
    return "" if n is None else n.ToCString()


def holes_of(faces: list[int], holes: list[CadHole]) -> list[CadHole]:
    """The holes with a wall among ``faces``."""
    fs = set(faces)
    return [h for h in holes if h.faces & fs]


class PmiFaces:
    """The faces PMI labels are attached to, as face-map numbers of the document's shape."""

    def __init__(self, doc: StepDocument) -> None:
        self.shapes = XCAFDoc_DocumentTool.ShapeTool_s(doc.doc.Main())
        self.map = face_map(doc.shape)

    def of(self, label: TDF_Label) -> list[int]:
        """The faces XCAF attaches ``label`` to (empty when it attaches it to none)."""
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

    def diameter_m(self, index: int) -> float | None:
        """A cylindrical face's diameter (m), None for another surface."""
        surf = BRepAdaptor_Surface(TopoDS.Face(self.map.FindKey(index)))
        if surf.GetType() != GeomAbs_Cylinder:
            return None
        return 2.0 * surf.Cylinder().Radius() * MM_TO_M

    def bore_of(self, hole: CadHole, faces: list[int]) -> float | None:
        """The diameter (m) of the bore of ``hole`` that ``faces`` are walls of (the largest
        when several; None when none of them is a cylindrical wall of the hole)."""
        sizes = [d for k in faces if k in hole.faces and (d := self.diameter_m(k)) is not None]
        return max(sizes) if sizes else None
