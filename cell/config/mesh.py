"""Mesh obstacles in the cell file: ``mesh: {path: frame.stl, scale: 0.001}``.

A shape entry of a cell file (part or environment obstacle, or a tool shape) may be a
triangle mesh instead of a primitive: ``path`` names an STL, OBJ or PLY file, relative to the
cell file's folder; ``scale`` turns the file's units into metres (0.001 for a CAD export in
millimetres). The mesh is used as given in collision checks (coal BVH, exact triangles).
"""

from __future__ import annotations

import functools
from pathlib import Path
from typing import Annotated

from pydantic import BaseModel, ConfigDict, Field

from robots.meshes import TriangleMesh, load_mesh


class MeshSpec(BaseModel):
    """A mesh file and the factor from its units to metres."""

    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)

    path: Annotated[str, Field(min_length=1)]
    scale: Annotated[float, Field(gt=0)] = 1.0

    def resolved(self, base_dir: Path | None) -> Path:
        """The file, relative paths taken from ``base_dir`` (the cell file's folder)."""
        p = Path(self.path).expanduser()
        return p if p.is_absolute() or base_dir is None else base_dir / p

    def load(self, base_dir: Path | None) -> TriangleMesh:
        """The mesh in metres (:class:`robots.meshes.MeshFileError` when it cannot be used)."""
        p = self.resolved(base_dir)
        stamp = p.stat().st_mtime_ns if p.is_file() else 0
        return _load_cached(str(p), stamp, self.scale)


@functools.lru_cache(maxsize=64)
def _load_cached(path: str, stamp: int, scale: float) -> TriangleMesh:
    del stamp  # part of the key only: a file changed on disk is read again
    return load_mesh(path, scale)
