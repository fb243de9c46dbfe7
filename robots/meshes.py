"""Triangle meshes for collision checks: read with trimesh, checked with coal BVH models.

A :class:`TriangleMesh` holds vertices (m, in the mesh's own frame, scale applied) and
triangles. STL, OBJ and PLY files are read; the mesh is used as given (no convex hull), so
a hollow part keeps its holes and openings, which is what an inspection tool reaches into.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import coal
import numpy as np
from numpy.typing import NDArray

from robots.errors import MeshFileError

#: mesh files read for mesh obstacles (trimesh); URDF link meshes also take .dae (assimp)
MESH_SUFFIXES = (".stl", ".obj", ".ply")


@dataclass(frozen=True, eq=False)
class TriangleMesh:
    """Vertices (N, 3) in metres and triangles (M, 3) as vertex indices."""

    vertices: NDArray[np.float64]
    faces: NDArray[np.int64]

    def geometry(self) -> coal.BVHModelOBBRSS:
        """The coal BVH model of this mesh (exact triangles, OBB-RSS tree)."""
        bvh = coal.BVHModelOBBRSS()
        bvh.beginModel(len(self.faces), len(self.vertices))
        bvh.addVertices(np.ascontiguousarray(self.vertices, dtype=np.float64))
        bvh.addTriangles(np.ascontiguousarray(self.faces, dtype=np.int64))
        bvh.endModel()
        return bvh

    def bounding_radius(self) -> float:
        """Radius (m) of a sphere about the mesh frame's origin that holds every vertex."""
        return float(np.max(np.linalg.norm(self.vertices, axis=1)))


def mesh_file_problem(path: Path, suffixes: tuple[str, ...] = MESH_SUFFIXES) -> str:
    """Why ``path`` cannot be a mesh file of one of ``suffixes`` ("" when it may be): the file
    checks shared by mesh obstacles (:func:`load_mesh`) and URDF link meshes
    (:mod:`robots.urdf_load`), which Pinocchio then reads."""
    if path.suffix.lower() not in suffixes:
        return f"not a mesh file (one of {', '.join(suffixes)})"
    if not path.exists():
        return "no such file"
    if not path.is_file():
        return "is not a file"
    if not os.access(path, os.R_OK):
        return "cannot be read (permission denied)"
    if path.stat().st_size == 0:
        return "is empty"
    return ""


def load_mesh(path: str | Path, scale: float = 1.0) -> TriangleMesh:
    """Read an STL, OBJ or PLY file; vertices multiplied by ``scale`` (file units to m)."""
    import trimesh  # imported here: only cells with mesh obstacles pay its import time

    p = Path(path)
    problem = mesh_file_problem(p)
    if problem:
        raise MeshFileError(str(p), problem)
    if not (np.isfinite(scale) and scale > 0):
        raise MeshFileError(str(p), f"scale must be a positive number, got {scale!r}")
    try:
        mesh = trimesh.load(p, force="mesh", process=False)
    except ImportError as exc:  # trimesh falls back to text decoding helpers on garbage
        raise MeshFileError(str(p), f"not a valid {p.suffix.lower()} mesh file") from exc
    except Exception as exc:  # trimesh raises many kinds on a corrupt file
        raise MeshFileError(str(p), f"cannot be read as a mesh: {exc}") from exc
    faces = np.asarray(getattr(mesh, "faces", np.zeros((0, 3))), dtype=np.int64)
    vertices = np.asarray(getattr(mesh, "vertices", np.zeros((0, 3))), dtype=np.float64)
    if len(faces) == 0 or len(vertices) < 3:
        raise MeshFileError(str(p), "holds no triangles")
    if not np.all(np.isfinite(vertices)):
        raise MeshFileError(str(p), "has non-finite vertex coordinates")
    return TriangleMesh(vertices * scale, faces)
