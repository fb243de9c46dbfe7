"""The holes of a part's shape: internal cylindrical walls all the way round, coaxial walls
joined into one hole (a counterbore: two diameters), each with its axis, the centre of its
entry circle, its diameter and depth, through or blind, and the outward normal (the side a
camera looks in from).

Left out, and counted: external cylinders (bosses, shafts, the outside of a tube),
cylinders that do not go all the way round (fillets, slots, half holes at an edge) and walls
closed at both ends (an enclosed void no camera sees).

The entry side (:mod:`cell.cad.hole_ends` finds the ends): of the open ends, one on a surface
that is not concave (a tube's outer wall, not the side facing into the tube), then the wider
bore (a counterbore's side), then the one whose normal points most along +z, then +x, then +y
of the part. No ray is cast: whether the camera can stand there is the planner's question.
The *measured* diameter is the entry bore's (the rim the camera sees at the surface); the other
bores are listed.
Depth: from the entry surface to the exit surface (through) or to the end of the innermost
cylindrical wall (blind: a drill point below it is not counted).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from OCP.TopoDS import TopoDS_Shape

from cell.cad.axes import Bore, Chain, chains
from cell.cad.cylinders import axial_faces, face_map
from cell.cad.hole_ends import End, ShapeProbe, chain_ends
from cell.cad.step_read import MM_TO_M


@dataclass(frozen=True)
class BoreSize:
    """One diameter of a hole and the length of its wall along the axis (m), entry first."""

    diameter_m: float
    length_m: float


@dataclass(frozen=True)
class CadHole:
    """A hole found in the CAD (m, part frame).

    ``entry_m`` the centre of the entry circle (where the axis leaves the part), ``normal``
    the unit axis pointing out of the part at the entry, ``diameter_m`` the measured (entry)
    bore's, ``bores`` every bore entry first, ``faces`` the face numbers of its walls (for the
    PMI that names them)."""

    id: str
    entry_m: tuple[float, float, float]
    normal: tuple[float, float, float]
    diameter_m: float
    depth_m: float
    through: bool
    bores: tuple[BoreSize, ...]
    faces: frozenset[int]
    countersunk: bool = False


@dataclass
class HoleScan:
    """What :func:`find_holes` found and what it left out (counts by reason)."""

    holes: list[CadHole]
    left_out: dict[str, int] = field(default_factory=dict)


def _entry_sign(low: End, high: End) -> float | None:
    """+1 or -1: the end the camera looks in from (module doc); None: a tie, or both closed."""
    opened = [e for e in (low, high) if e.open]
    if not opened:
        return None
    if len(opened) == 1:
        return opened[0].sign

    def key(e: End) -> tuple[bool, float]:
        return (not e.concave, round(e.radius, 6))

    return None if key(low) == key(high) else max(opened, key=key).sign


def _tie_break(direction: np.ndarray) -> float:
    """+1 when ``direction`` points more along +z (then +x, +y) than its opposite."""
    for k in (2, 0, 1):
        if abs(direction[k]) > 1e-9:
            return 1.0 if direction[k] > 0 else -1.0
    return 1.0


def _hole(probe: ShapeProbe, chain: Chain) -> CadHole | None:
    low, high = chain_ends(probe, chain)
    if not (low.open or high.open):
        return None
    sign = _entry_sign(low, high)
    if sign is None:
        sign = _tie_break(chain.direction)
    entry, exit_ = (high, low) if sign > 0 else (low, high)
    through = low.open and high.open
    bores: list[Bore] = chain.bores if sign < 0 else chain.bores[::-1]
    inner_end = bores[-1].t_range[0] if sign > 0 else bores[-1].t_range[1]
    t_exit = exit_.t if through else inner_end
    normal = sign * chain.direction
    centre = (chain.origin + entry.t * chain.direction) * MM_TO_M
    return CadHole(
        id="",
        entry_m=(float(centre[0]), float(centre[1]), float(centre[2])),
        normal=(float(normal[0]) + 0.0, float(normal[1]) + 0.0, float(normal[2]) + 0.0),
        diameter_m=2.0 * bores[0].radius * MM_TO_M,
        depth_m=abs(entry.t - t_exit) * MM_TO_M,
        through=through,
        bores=tuple(
            BoreSize(2.0 * b.radius * MM_TO_M, (b.t_range[1] - b.t_range[0]) * MM_TO_M)
            for b in bores
        ),
        faces=frozenset(chain.face_indices()),
        countersunk=bool(chain.cones),
    )


def find_holes(shape: TopoDS_Shape, prefix: str = "H") -> HoleScan:
    """The holes of ``shape`` (OpenCascade, mm), numbered ``H1``... in the order of their
    entry centres (x, then y, then z, to the micrometre)."""
    faces = face_map(shape)
    axial = axial_faces(faces)
    found, partial = chains(axial)
    probe = ShapeProbe(shape, faces, axial)
    holes, enclosed = [], 0
    for chain in found:
        hole = _hole(probe, chain)
        if hole is None:
            enclosed += 1
        else:
            holes.append(hole)
    holes.sort(key=lambda h: tuple(round(v * 1e6) for v in h.entry_m))
    width = len(str(len(holes)))
    numbered = [
        CadHole(**{**h.__dict__, "id": f"{prefix}{i:0{width}d}"}) for i, h in enumerate(holes, 1)
    ]
    left_out = {
        "external cylinders (bosses, shafts)": sum(
            1 for f in axial if f.kind == "cylinder" and not f.internal
        ),
        "internal cylinders not all round (fillets, slots)": len(partial),
        "holes closed at both ends": enclosed,
    }
    return HoleScan(numbered, {k: v for k, v in left_out.items() if v})
