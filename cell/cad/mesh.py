"""The part's collision mesh from its CAD: OpenCascade's tessellation (``BRepMesh``) at a
stated deflection, in metres, written as a binary STL when asked.

``deflection_m`` is the largest distance between a triangle and the true surface (linear
deflection); ``angle_rad`` the largest angle between neighbouring triangles' normals on a
curved face. The mesh keeps every hole: the cell's collision checks see the part as drawn.
"""

from __future__ import annotations

import struct
from pathlib import Path

import numpy as np
from OCP.BRep import BRep_Tool
from OCP.BRepMesh import BRepMesh_IncrementalMesh
from OCP.TopAbs import TopAbs_FACE, TopAbs_REVERSED
from OCP.TopExp import TopExp_Explorer
from OCP.TopLoc import TopLoc_Location
from OCP.TopoDS import TopoDS, TopoDS_Shape

from cell.cad.errors import CadError
from cell.cad.step_read import MM_TO_M
from robots.meshes import TriangleMesh

#: default linear deflection (m) and angular deflection (rad)
DEFLECTION_M = 0.2e-3
ANGLE_RAD = 0.35


def tessellate(
    shape: TopoDS_Shape, deflection_m: float = DEFLECTION_M, angle_rad: float = ANGLE_RAD
) -> TriangleMesh:
    """The triangles of ``shape`` (OpenCascade, mm) in metres, outward-facing."""
    if not deflection_m > 0:
        raise CadError("mesh", "deflection_m", f"must be > 0 m, got {deflection_m!r}")
    BRepMesh_IncrementalMesh(shape, deflection_m / MM_TO_M, False, angle_rad, True)
    verts: list[np.ndarray] = []
    tris: list[np.ndarray] = []
    n = 0
    ex = TopExp_Explorer(shape, TopAbs_FACE)
    while ex.More():
        face = TopoDS.Face(ex.Current())
        loc = TopLoc_Location()
        tri = BRep_Tool.Triangulation_s(face, loc)
        ex.Next()
        if tri is None:
            continue
        trsf = loc.Transformation()
        pts = np.array(
            [
                (lambda p: (p.X(), p.Y(), p.Z()))(tri.Node(i).Transformed(trsf))
                for i in range(1, tri.NbNodes() + 1)
            ]
        )
        idx = np.array([tri.Triangle(i).Get() for i in range(1, tri.NbTriangles() + 1)]) - 1
        if face.Orientation() == TopAbs_REVERSED:
            idx = idx[:, ::-1]
        verts.append(pts)
        tris.append(idx + n)
        n += len(pts)
    if not tris:
        raise CadError("mesh", "shape", "no face could be tessellated")
    return TriangleMesh(np.vstack(verts) * MM_TO_M, np.vstack(tris).astype(np.int64))


def write_stl(mesh: TriangleMesh, path: str | Path, scale: float = 1.0) -> Path:
    """A binary STL of ``mesh`` with coordinates multiplied by ``scale`` (1: metres)."""
    p = Path(path)
    v = mesh.vertices * scale
    tri = v[mesh.faces]
    normals = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    lengths = np.linalg.norm(normals, axis=1, keepdims=True)
    normals = np.divide(normals, lengths, out=np.zeros_like(normals), where=lengths > 0)
    records = np.zeros(len(tri), dtype=[("n", "<f4", 3), ("v", "<f4", (3, 3)), ("attr", "<u2")])
    records["n"], records["v"] = normals, tri
    with p.open("wb") as fh:
        fh.write(b"holecell import-step".ljust(80, b" "))
        fh.write(struct.pack("<I", len(tri)))
        fh.write(records.tobytes())
    return p
