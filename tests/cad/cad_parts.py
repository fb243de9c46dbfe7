"""STEP test parts generated with build123d, each with the holes its script cut (the truth):
plates with through, blind and counterbored holes, a tube with cross holes, holes on angled
faces (square to the face and not), and a frame-like weldment of plates at compound angles.

Lengths in the scripts are millimetres (build123d's default); the truth is in metres. A
uniquely named module (test modules import from it)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from build123d import Align, Box, Cylinder, Location, Part, Plane, Pos, export_step
from OCP.gp import gp_Pnt, gp_Vec


@dataclass(frozen=True)
class TrueHole:
    """A hole as the script cut it (m): entry centre, outward unit normal, the entry bore's
    diameter, depth, through, every bore's diameter entry first."""

    entry_m: tuple[float, float, float]
    normal: tuple[float, float, float]
    diameter_m: float
    depth_m: float
    through: bool
    bores_m: tuple[float, ...]


def _unit(v) -> np.ndarray:
    v = np.asarray(v, dtype=float)
    return v / np.linalg.norm(v)


def drill(origin_mm, normal, diameter_mm: float, depth_mm: float, over_mm: float = 2.0) -> Part:
    """A cylinder that cuts a hole of ``depth_mm`` into the material from ``origin_mm`` on the
    surface, against ``normal`` (sticking out ``over_mm`` above the surface)."""
    plane = Plane(origin=tuple(origin_mm), z_dir=tuple(_unit(normal)))
    tool = Cylinder(
        diameter_mm / 2, depth_mm + over_mm, align=(Align.CENTER, Align.CENTER, Align.MAX)
    )
    return Location(plane) * (Pos(0, 0, over_mm) * tool)


def _true(entry_mm, normal, d_mm, depth_mm, through, bores_mm) -> TrueHole:
    n = _unit(normal)
    return TrueHole(
        tuple(float(v) * 1e-3 for v in entry_mm),
        tuple(float(v) for v in n),
        d_mm * 1e-3,
        depth_mm * 1e-3,
        through,
        tuple(b * 1e-3 for b in bores_mm),
    )


def plate() -> tuple[Part, list[TrueHole]]:
    """A 120 x 80 x 12 plate: 3 through holes, 2 blind, 2 counterbored (through)."""
    part = Box(120, 80, 12)  # z from -6 to 6
    top = 6.0
    holes, tools = [], []
    for x, y, d in ((-45, -25, 6.0), (-45, 25, 8.5), (0, -25, 10.0)):
        tools.append(drill((x, y, top), (0, 0, 1), d, 12 + 2))
        holes.append(_true((x, y, top), (0, 0, 1), d, 12, True, (d,)))
    for x, y, d, depth in ((0, 25, 5.0, 7.0), (45, -25, 4.2, 3.5)):
        tools.append(drill((x, y, top), (0, 0, 1), d, depth))
        holes.append(_true((x, y, top), (0, 0, 1), d, depth, False, (d,)))
    for x, y, d, cd, cdepth in ((45, 25, 6.6, 11.0, 6.4), (22, 0, 9.0, 15.0, 8.6)):
        tools.append(drill((x, y, top), (0, 0, 1), d, 12 + 2))
        tools.append(drill((x, y, top), (0, 0, 1), cd, cdepth))
        holes.append(_true((x, y, top), (0, 0, 1), cd, 12, True, (cd, d)))
    return part - tools, holes


def tube() -> tuple[Part, list[TrueHole]]:
    """A tube along x (outer radius 20, inner 16, 200 long): its bore (a through hole seen
    from +x), two radial holes through the top wall, one through both walls (two holes)."""
    r_out, r_in, length = 20.0, 16.0, 200.0
    body = Cylinder(r_out, length, rotation=(0, 90, 0)) - Cylinder(
        r_in, length, rotation=(0, 90, 0)
    )
    holes = [_true((length / 2, 0, 0), (1, 0, 0), 2 * r_in, length, True, (2 * r_in,))]
    tools = []
    for x, d in ((-60.0, 6.0), (-20.0, 8.0)):
        tools.append(drill((x, 0, r_out), (0, 0, 1), d, r_out - r_in + 3))
        holes.append(_true((x, 0, r_out), (0, 0, 1), d, r_out - r_in, True, (d,)))
    # one drill through both walls along y: two holes, each seen from outside
    tools.append(drill((40.0, r_out, 0), (0, 1, 0), 5.0, 2 * r_out + 4))
    holes.append(_true((40.0, r_out, 0), (0, 1, 0), 5.0, r_out - r_in, True, (5.0,)))
    holes.append(_true((40.0, -r_out, 0), (0, -1, 0), 5.0, r_out - r_in, True, (5.0,)))
    return body - tools, holes


def angled() -> tuple[Part, list[TrueHole]]:
    """A block whose top is a face sloped 30 deg about y: a blind hole square to the face,
    a through hole square to it, and a vertical through hole crossing the face at an angle."""
    a = math.radians(30)
    n = np.array([-math.sin(a), 0.0, math.cos(a)])
    block = Box(100, 60, 60)  # z -30..30
    cut = Location(Plane(origin=(0, 0, 10), z_dir=tuple(n))) * Pos(0, 0, 50) * Box(300, 300, 100)
    part = block - cut
    p0 = np.array([0.0, 0.0, 10.0])
    u = np.array([math.cos(a), 0.0, math.sin(a)])  # along the face, up the slope
    holes, tools = [], []
    e1 = p0 + 15 * u + np.array([0, -15, 0])
    tools.append(drill(e1, n, 7.0, 18.0))
    holes.append(_true(e1, n, 7.0, 18.0, False, (7.0,)))
    e2 = p0 - 20 * u + np.array([0, 15, 0])
    tools.append(drill(e2, n, 5.0, 120.0))
    # square to the face: leaves through the bottom (z = -30) or the side (x = -50)
    t_bottom = (e2[2] + 30) / n[2]
    t_side = (e2[0] + 50) / -n[0]
    holes.append(_true(e2, n, 5.0, min(t_bottom, t_side), True, (5.0,)))
    # vertical through hole at x = 25: the axis crosses the face where z = 10 + x tan(a)
    x3 = 25.0
    e3 = np.array([x3, 0.0, 10.0 + x3 * math.tan(a)])
    tools.append(drill(e3 + np.array([0.0, 0.0, 5.0]), (0, 0, 1), 6.0, 100.0, over_mm=10))
    holes.append(_true(e3, (0, 0, 1), 6.0, e3[2] + 30, True, (6.0,)))
    return part - tools, holes


def weldment() -> tuple[Part, list[TrueHole]]:
    """A frame-like weldment: a base plate, two gusset plates at compound angles welded on it
    (tilt 20 and 35 deg, yaw 25 and -40 deg), each with a hole square to it."""
    base = Box(300, 160, 10)  # z -5..5
    holes, tools = [], []
    for x in (-120.0, 120.0):
        tools.append(drill((x, 60, 5), (0, 0, 1), 10.0, 12.0))
        holes.append(_true((x, 60, 5), (0, 0, 1), 10.0, 10.0, True, (10.0,)))
    parts = [base]
    for cx, tilt, yaw, d in ((-60.0, 20.0, 25.0, 8.0), (70.0, 35.0, -40.0, 12.0)):
        frame = Plane(origin=(cx, -20, 30)).rotated((tilt, 0, yaw))
        loc = Location(frame)
        parts.append(loc * Box(80, 8, 60))  # the plate's normal is its local y
        T = loc.wrapped.Transformation()
        v = gp_Vec(0, 1, 0).Transformed(T)
        p = gp_Pnt(0, 4, 10).Transformed(T)
        n = (v.X(), v.Y(), v.Z())
        entry = (p.X(), p.Y(), p.Z())
        tools.append(drill(entry, n, d, 8 + 2))
        holes.append(_true(entry, n, d, 8.0, True, (d,)))
    whole = parts[0]
    for q in parts[1:]:
        whole = whole + q
    return whole - tools, holes


GENERATORS = {"plate": plate, "tube": tube, "angled": angled, "weldment": weldment}


def write_part(name: str, folder: Path) -> tuple[Path, list[TrueHole]]:
    """Generate part ``name``, write it as STEP in ``folder``; the file and its holes."""
    part, holes = GENERATORS[name]()
    path = folder / f"{name}.step"
    export_step(part, str(path))
    return path, holes
