"""A part from its STEP file: holes, PMI and collision mesh in one pass, with the time each
stage took (s).

:func:`hole_rows` gives the holes as cell-file hole mappings (m): what ``part.step:`` adds to
a cell file and what ``holecell import-step`` writes as a holes CSV.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from cell.cad.holes import CadHole, HoleScan, find_holes
from cell.cad.mesh import ANGLE_RAD, DEFLECTION_M, tessellate
from cell.cad.pmi import Pmi, read_pmi
from cell.cad.step_read import read_step
from robots.meshes import TriangleMesh


@dataclass
class ImportedPart:
    """What :func:`import_step` read: the holes, the PMI, the mesh (None unless asked for)."""

    path: Path
    schema: str
    scan: HoleScan
    pmi: Pmi
    mesh: TriangleMesh | None
    deflection_m: float
    timings_s: dict[str, float] = field(default_factory=dict)


def import_step(
    path: str | Path,
    *,
    mesh: bool = True,
    deflection_m: float = DEFLECTION_M,
    angle_rad: float = ANGLE_RAD,
) -> ImportedPart:
    """Read ``path``: holes, PMI matched to them, and (``mesh``) the tessellated part."""
    t0 = time.perf_counter()
    doc = read_step(path)
    t1 = time.perf_counter()
    scan = find_holes(doc.shape)
    t2 = time.perf_counter()
    pmi = read_pmi(doc, scan.holes)
    t3 = time.perf_counter()
    tri = tessellate(doc.shape, deflection_m, angle_rad) if mesh else None
    t4 = time.perf_counter()
    timings = {"read": t1 - t0, "holes": t2 - t1, "pmi": t3 - t2, "mesh": t4 - t3}
    return ImportedPart(doc.path, doc.schema, scan, pmi, tri, deflection_m, timings)


def _bores_text(h: CadHole) -> str:
    """``11@6.4 6.6@3.6``: each bore's diameter@length in mm, entry first."""
    return " ".join(f"{b.diameter_m * 1e3:.6g}@{b.length_m * 1e3:.6g}" for b in h.bores)


def hole_rows(part: ImportedPart) -> list[dict[str, Any]]:
    """The holes as cell-file hole mappings (m), with their PMI tolerances where the STEP
    has them and the CSV's extra columns under ``extra``."""
    rows = []
    for h in part.scan.holes:
        row: dict[str, Any] = {
            "id": h.id,
            "position": list(h.entry_m),
            "normal": list(h.normal),
            "diameter": h.diameter_m,
            "extra": {
                "depth_mm": f"{h.depth_m * 1e3:.6g}",
                "through": "yes" if h.through else "no",
                "bores_mm": _bores_text(h),
            },
        }
        tol = part.pmi.tolerances.get(h.id)
        if tol:
            row["tolerances"] = tol
        rows.append(row)
    return rows
