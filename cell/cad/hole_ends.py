"""The two ends of a hole: open or closed, where the axis crosses the part's surface there
(the centre of the entry or exit circle), and whether that surface is concave (the inside of
a tube: a camera there would stand inside the part).

Shape units (OpenCascade's millimetres). Topology decides, no ray is cast: at each end the
*end face* is the face around the hole whose surface the axis crosses outermost on that half
of the hole. The end is closed when that face's outer boundary is made of the hole's own
edges only (a flat bottom: a disc bounded by the wall's circle) or when nothing is there (a
drill point ends in the cone's apex); otherwise the hole opens into the face.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from OCP.BRep import BRep_Tool
from OCP.BRepTools import BRepTools
from OCP.collections import (
    IndexedDataMap_TopoDS_Shape_List_TopoDS_Shape_TopTools_ShapeMapHasher as EdgeFaces,
)
from OCP.collections import IndexedMap_TopoDS_Shape_TopTools_ShapeMapHasher as ShapeMap
from OCP.Geom import Geom_Line
from OCP.GeomAPI import GeomAPI_IntCS
from OCP.gp import gp_Dir, gp_Lin, gp_Pnt
from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE
from OCP.TopExp import TopExp, TopExp_Explorer
from OCP.TopoDS import TopoDS, TopoDS_Shape

from cell.cad.axes import Chain
from cell.cad.cylinders import AxialFace

#: axis crossings this far outside the hole's extent still count (shape units)
MARGIN = 1e-3


@dataclass(frozen=True)
class End:
    """One end of a chain: ``sign`` +1 for the end at the high ``t``, -1 for the low one;
    ``t`` the axial coordinate of the crossing with the end face (the wall's end when none);
    ``open`` whether the hole opens there; ``concave`` whether the end face is the inside of
    a cylinder or cone (a tube's bore); ``radius`` the bore's there."""

    sign: float
    t: float
    open: bool
    concave: bool
    radius: float


class ShapeProbe:
    """Face adjacency, outer boundaries and surfaces of one shape, set up once."""

    def __init__(self, shape: TopoDS_Shape, faces: ShapeMap, axial: list[AxialFace]) -> None:
        self.faces = faces
        self.edges = ShapeMap()
        TopExp.MapShapes_s(shape, TopAbs_EDGE, self.edges)
        edge_faces = EdgeFaces()
        TopExp.MapShapesAndAncestors_s(shape, TopAbs_EDGE, TopAbs_FACE, edge_faces)
        self.face_edges: dict[int, set[int]] = {}
        self.edge_faces: dict[int, set[int]] = {}
        for i in range(1, edge_faces.Extent() + 1):
            e = self.edges.FindIndex(edge_faces.FindKey(i))
            fs = {faces.FindIndex(f) for f in edge_faces.FindFromIndex(i)}
            self.edge_faces[e] = fs
            for f in fs:
                self.face_edges.setdefault(f, set()).add(e)
        self.internal = {a.index for a in axial if a.internal}
        self._outer: dict[int, set[int]] = {}

    def neighbours(self, indices: set[int]) -> set[int]:
        """Face numbers sharing an edge with the faces ``indices``, those left out."""
        out: set[int] = set()
        for i in indices:
            for e in self.face_edges.get(i, ()):
                out |= self.edge_faces[e]
        return out - indices

    def outer_edges(self, face: int) -> set[int]:
        """Edge numbers of the outer boundary of face ``face``."""
        if face not in self._outer:
            wire = BRepTools.OuterWire_s(TopoDS.Face(self.faces.FindKey(face)))
            found: set[int] = set()
            ex = TopExp_Explorer(wire, TopAbs_EDGE)
            while ex.More():
                found.add(self.edges.FindIndex(ex.Current()))
                ex.Next()
            self._outer[face] = found
        return self._outer[face]

    def axis_crossings(
        self, faces: set[int], origin: np.ndarray, direction: np.ndarray
    ) -> list[tuple[float, int]]:
        """Where the axis line crosses the surfaces of ``faces``: (axial coordinate, face)."""
        line = Geom_Line(gp_Lin(gp_Pnt(*origin), gp_Dir(*direction)))
        found: list[tuple[float, int]] = []
        for i in sorted(faces):
            surface = BRep_Tool.Surface_s(TopoDS.Face(self.faces.FindKey(i)))
            inter = GeomAPI_IntCS(line, surface)
            if not inter.IsDone():
                continue
            for k in range(1, inter.NbPoints() + 1):
                p = inter.Point(k)
                t = float(np.dot(np.array([p.X(), p.Y(), p.Z()]) - origin, direction))
                found.append((t, i))
        return found


def end_face(probe: ShapeProbe, chain: Chain, sign: float) -> tuple[float, int] | None:
    """The crossing (axial coordinate, face) of the axis with the face around the hole that
    lies outermost on the ``sign`` half of the chain (an angled face: the middle of the
    ellipse; a tube: its wall), or None when no face around the hole crosses there."""
    lo, hi = chain.t_range
    mid = 0.5 * (lo + hi)
    lo, hi = (mid, hi) if sign > 0 else (lo, mid)
    around = probe.neighbours(chain.face_indices())
    hits = [
        (t, f)
        for t, f in probe.axis_crossings(around, chain.origin, chain.direction)
        if lo - MARGIN <= t <= hi + MARGIN
    ]
    if not hits:
        return None
    return max(hits) if sign > 0 else min(hits)


def chain_ends(probe: ShapeProbe, chain: Chain) -> tuple[End, End]:
    """The low and the high end of ``chain`` (module doc)."""
    lo, hi = chain.t_range
    walls = set()
    for i in chain.face_indices():
        walls |= probe.face_edges.get(i, set())
    ends = []
    for sign, t_wall in ((-1.0, lo), (1.0, hi)):
        bore = chain.bores[0] if sign < 0 else chain.bores[-1]
        crossing = end_face(probe, chain, sign)
        if crossing is None:
            ends.append(End(sign, t_wall, False, False, bore.radius))
            continue
        t, face = crossing
        closed = probe.outer_edges(face) <= walls
        ends.append(End(sign, t, not closed, face in probe.internal, bore.radius))
    return ends[0], ends[1]
