"""The two ends of a hole: open or closed, how far the axis is free beyond each, and where the
axis crosses the part's surface there (the centre of the entry and exit circles).

Shape units (OpenCascade's millimetres). An end is *closed* when a ray cast from it outward
along the axis meets the part within 0.6 diameters (a flat bottom at once, a drill point of
118 degrees at 0.3 d); otherwise it is open and the ray's free length is how far a camera
could look in along the axis (capped at ``clear``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from OCP.BRep import BRep_Tool
from OCP.collections import (
    IndexedDataMap_TopoDS_Shape_List_TopoDS_Shape_TopTools_ShapeMapHasher as EdgeFaces,
)
from OCP.collections import IndexedMap_TopoDS_Shape_TopTools_ShapeMapHasher as FaceMap
from OCP.Geom import Geom_Line
from OCP.GeomAPI import GeomAPI_IntCS
from OCP.gp import gp_Dir, gp_Lin, gp_Pnt
from OCP.IntCurvesFace import IntCurvesFace_ShapeIntersector
from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE
from OCP.TopExp import TopExp, TopExp_Explorer
from OCP.TopoDS import TopoDS, TopoDS_Shape

from cell.cad.axes import Chain

#: a closed end's bottom lies within this many diameters of it
BOTTOM_DIAMETERS = 0.6
#: the ray starts this far inside the hole (shape units)
EPS = 1e-3


@dataclass(frozen=True)
class End:
    """One end of a chain: ``sign`` +1 for the end at the high ``t``, -1 for the low one;
    ``t`` its axial coordinate; ``free`` the free length beyond it along the axis (inf when
    the ray leaves the part), ``open`` whether a camera sees into the hole from there."""

    sign: float
    t: float
    free: float
    open: bool
    radius: float


class ShapeProbe:
    """Ray casts and face neighbours on one shape, set up once."""

    def __init__(self, shape: TopoDS_Shape, faces: FaceMap) -> None:
        self.faces = faces
        self.rays = IntCurvesFace_ShapeIntersector()
        self.rays.Load(shape, 1e-7)
        self.edge_faces = EdgeFaces()
        TopExp.MapShapesAndAncestors_s(shape, TopAbs_EDGE, TopAbs_FACE, self.edge_faces)

    def free_length(self, start: np.ndarray, direction: np.ndarray) -> float:
        """Distance from ``start`` along ``direction`` to the first face met (inf: none)."""
        line = gp_Lin(gp_Pnt(*start), gp_Dir(*direction))
        self.rays.Perform(line, 0.0, math.inf)
        if not self.rays.IsDone() or self.rays.NbPnt() == 0:
            return math.inf
        return min(self.rays.WParameter(i) for i in range(1, self.rays.NbPnt() + 1))

    def neighbours(self, indices: set[int]) -> set[int]:
        """Face numbers sharing an edge with the faces ``indices``, those left out."""
        out: set[int] = set()
        for i in indices:
            ex = TopExp_Explorer(self.faces.FindKey(i), TopAbs_EDGE)
            while ex.More():
                for f in self.edge_faces.FindFromKey(ex.Current()):
                    out.add(self.faces.FindIndex(f))
                ex.Next()
        return out - indices

    def axis_crossings(self, faces: set[int], origin: np.ndarray, direction: np.ndarray) -> list[float]:
        """Where the axis line crosses the surfaces of ``faces`` (axial coordinates)."""
        line = Geom_Line(gp_Lin(gp_Pnt(*origin), gp_Dir(*direction)))
        ts: list[float] = []
        for i in faces:
            surface = BRep_Tool.Surface_s(TopoDS.Face(self.faces.FindKey(i)))
            inter = GeomAPI_IntCS(line, surface)
            if not inter.IsDone():
                continue
            for k in range(1, inter.NbPoints() + 1):
                p = inter.Point(k)
                ts.append(float(np.dot(np.array([p.X(), p.Y(), p.Z()]) - origin, direction)))
        return ts


def chain_ends(probe: ShapeProbe, chain: Chain, clear: float) -> tuple[End, End]:
    """The low and the high end of ``chain``; ``clear`` caps the free lengths."""
    lo, hi = chain.t_range
    ends = []
    for sign, t in ((-1.0, lo), (1.0, hi)):
        end_bore = chain.bores[0] if sign < 0 else chain.bores[-1]
        start = chain.origin + (t - sign * EPS) * chain.direction
        free = probe.free_length(start, sign * chain.direction) - EPS
        closed = free < BOTTOM_DIAMETERS * 2.0 * end_bore.radius
        ends.append(End(sign, t, min(free, clear), not closed, end_bore.radius))
    return ends[0], ends[1]


def surface_crossing(probe: ShapeProbe, chain: Chain, sign: float) -> float | None:
    """The axial coordinate where the hole's axis leaves the part at its ``sign`` end: the
    crossing of the axis with the surfaces around the hole that lies outermost within the
    half of the chain's extent at that end (an angled face: the middle of the ellipse; a
    tube: its outer wall)."""
    lo, hi = chain.t_range
    mid = 0.5 * (lo + hi)
    # the crossings on this end's half of the hole (the other half is the other end's)
    lo, hi = (mid, hi) if sign > 0 else (lo, mid)
    around = probe.neighbours(chain.face_indices())
    ts = [
        t
        for t in probe.axis_crossings(around, chain.origin, chain.direction)
        if lo - 1e-3 <= t <= hi + 1e-3
    ]
    if not ts:
        return None
    return max(ts) if sign > 0 else min(ts)
