"""The axial faces of a shape: cylinders (hole walls, bosses, fillets) and cones (countersinks,
chamfers, drill points), each with its axis, radius, the side its material is on and the
interval of the axis it covers.

Lengths in the shape's unit (OpenCascade's millimetres). A cylinder is *internal* (a hole's
wall) when the face's outward normal, the side away from the material, points toward the
axis; a boss or the outside of a tube points away from it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from OCP.BRepAdaptor import BRepAdaptor_Surface
from OCP.BRepTools import BRepTools
from OCP.collections import IndexedMap_TopoDS_Shape_TopTools_ShapeMapHasher
from OCP.GeomAbs import GeomAbs_Cone, GeomAbs_Cylinder
from OCP.TopAbs import TopAbs_FACE, TopAbs_REVERSED
from OCP.TopExp import TopExp
from OCP.TopoDS import TopoDS, TopoDS_Shape


@dataclass(frozen=True)
class AxialFace:
    """One cylindrical or conical face.

    ``index`` is the face's number in the shape's face map (1-based, stable for one shape);
    ``origin`` a point of the axis and ``direction`` its unit vector, the sign made canonical
    (largest component positive) so coaxial faces share it; ``t_range`` the interval of the
    axis the face covers, measured along ``direction`` from ``origin``; ``u_range`` its
    angular extent (rad) about ``direction``, from a reference that depends on ``direction``
    only (:func:`_reference`), so that faces of one axis compare whatever their own surfaces'
    x directions and handedness (some exporters write a hole's two halves as u 0..pi each, on
    x directions half a turn apart: NIST CTC-03, FTC-07, FTC-09 in AP242); ``radius`` the
    cylinder's radius (a cone's radii at both ends in ``radii``); ``internal`` True when the
    material is outside the radius (a hole).
    """

    index: int
    kind: str
    origin: np.ndarray
    direction: np.ndarray
    radius: float
    radii: tuple[float, float]
    t_range: tuple[float, float]
    u_range: tuple[float, float]
    internal: bool


def face_map(shape: TopoDS_Shape) -> IndexedMap_TopoDS_Shape_TopTools_ShapeMapHasher:
    """Every face of ``shape`` once, numbered from 1."""
    faces = IndexedMap_TopoDS_Shape_TopTools_ShapeMapHasher()
    TopExp.MapShapes_s(shape, TopAbs_FACE, faces)
    return faces


def _vec(d) -> np.ndarray:
    return np.array([d.X(), d.Y(), d.Z()])


def canonical(direction: np.ndarray) -> float:
    """+1 or -1: the sign that makes ``direction``'s largest component positive."""
    k = int(np.argmax(np.abs(direction)))
    return 1.0 if direction[k] > 0 else -1.0


def _reference(direction: np.ndarray) -> np.ndarray:
    """A unit vector square to ``direction`` that depends on it alone: the world axis least
    along it (the first of near ties), made square."""
    k = int(np.flatnonzero(np.abs(direction) <= np.abs(direction).min() + 1e-3)[0])
    e = np.zeros(3)
    e[k] = 1.0
    r = e - np.dot(e, direction) * direction
    return r / np.linalg.norm(r)


def _angles(ax3, direction: np.ndarray, umin: float, umax: float) -> tuple[float, float]:
    """A face's u interval as angles about ``direction`` from :func:`_reference` (rad)."""
    ref = _reference(direction)
    x = _vec(ax3.XDirection())
    offset = math.atan2(float(np.dot(np.cross(ref, x), direction)), float(np.dot(ref, x)))
    # u turns counterclockwise about the surface's own axis on a right-handed frame
    sense = float(np.sign(np.dot(_vec(ax3.Direction()), direction)))
    if not ax3.Direct():
        sense = -sense
    a, b = offset + sense * umin, offset + sense * umax
    return (min(a, b), max(a, b))


def _axial(index: int, face, kind: str) -> AxialFace | None:
    surf = BRepAdaptor_Surface(face)
    stype = surf.GetType()
    if stype not in (GeomAbs_Cylinder, GeomAbs_Cone):
        return None
    umin, umax, vmin, vmax = BRepTools.UVBounds_s(face)
    if stype == GeomAbs_Cylinder:
        geom = surf.Cylinder()
        ax3 = geom.Position()
        r_ref, half = geom.Radius(), 0.0
        kind = "cylinder"
    else:
        geom = surf.Cone()
        ax3 = geom.Position()
        r_ref, half = geom.RefRadius(), geom.SemiAngle()
        kind = "cone"
    z = _vec(ax3.Direction())
    sign = canonical(z)
    origin = _vec(ax3.Location())
    # a cone's point at (u, v) lies at axial distance v cos(half), radius r_ref + v sin(half)
    scale = math.cos(half)
    t = sorted((sign * vmin * scale, sign * vmax * scale))
    radii = (r_ref + vmin * math.sin(half), r_ref + vmax * math.sin(half))
    # the surface's own normal is radial outward on a right-handed frame, inward otherwise
    # (a cone's radial part likewise); a reversed face turns it round
    outward = 1.0 if ax3.Direct() else -1.0
    if face.Orientation() == TopAbs_REVERSED:
        outward = -outward
    return AxialFace(
        index=index,
        kind=kind,
        origin=origin,
        direction=sign * z,
        radius=r_ref,
        radii=(min(radii), max(radii)),
        t_range=(t[0], t[1]),
        u_range=_angles(ax3, sign * z, umin, umax),
        internal=outward < 0,
    )


def axial_faces(faces: IndexedMap_TopoDS_Shape_TopTools_ShapeMapHasher) -> list[AxialFace]:
    """The cylindrical and conical faces among ``faces``."""
    out = []
    for i in range(1, faces.Extent() + 1):
        a = _axial(i, TopoDS.Face(faces.FindKey(i)), "")
        if a is not None:
            out.append(a)
    return out


def covered_angle(ranges: list[tuple[float, float]]) -> float:
    """The angle (rad, at most 2 pi) covered by the union of ``ranges`` taken modulo 2 pi."""
    two_pi = 2.0 * math.pi
    pieces: list[tuple[float, float]] = []
    for a, b in ranges:
        if b - a >= two_pi - 1e-9:
            return two_pi
        a0 = a % two_pi
        b0 = a0 + (b - a)
        if b0 <= two_pi:
            pieces.append((a0, b0))
        else:
            pieces += [(a0, two_pi), (0.0, b0 - two_pi)]
    pieces.sort()
    total, end = 0.0, -1.0
    for a, b in pieces:
        if a > end:
            total += b - a
            end = b
        elif b > end:
            total += b - end
            end = b
    return min(total, two_pi)
