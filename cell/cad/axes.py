"""Coaxial grouping: axial faces on one axis line, joined along it into chains.

A *bore* is the set of internal cylindrical faces of one radius on one axis whose intervals
touch (a wall split into several faces, around or along the axis, is one bore); a bore whose
faces together go all the way round (2 pi) is a hole's wall, one that does not is a fillet or
a slot and is left out. A *chain* is a run of bores and coaxial internal cones touching along
the axis (a counterbore: two bores; a countersink: a cone and a bore): one hole.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

from cell.cad.cylinders import AxialFace, covered_angle

#: faces on one axis line: distance between their lines (shape units) and angle (rad)
LINE_TOL = 1e-4
ANGLE_TOL = 1e-7
#: radii equal within this (shape units); intervals touching within this
RADIUS_TOL = 1e-4
TOUCH_TOL = 1e-4


@dataclass
class Bore:
    """Internal cylindrical faces of one radius, joined along the axis: ``t_range`` on the
    chain's axis (shape units), ``full`` when they go all the way round."""

    radius: float
    t_range: tuple[float, float]
    faces: list[AxialFace]
    full: bool


@dataclass
class Chain:
    """One hole's walls: bores (and cones) on one axis, touching along it, in axial order.
    ``origin`` and ``direction`` (unit, canonical sign) define the axis coordinate ``t``."""

    origin: np.ndarray
    direction: np.ndarray
    bores: list[Bore]
    cones: list[tuple[tuple[float, float], AxialFace]] = field(default_factory=list)

    @property
    def t_range(self) -> tuple[float, float]:
        ts = [b.t_range for b in self.bores] + [c[0] for c in self.cones]
        return min(t[0] for t in ts), max(t[1] for t in ts)

    def face_indices(self) -> set[int]:
        """Face-map numbers of every face of the chain."""
        return {f.index for b in self.bores for f in b.faces} | {c[1].index for c in self.cones}


def _line_key(f: AxialFace) -> np.ndarray:
    """The axis line as 6 numbers: its point nearest the origin, and its direction scaled so
    that ANGLE_TOL weighs as LINE_TOL."""
    p0 = f.origin - np.dot(f.origin, f.direction) * f.direction
    return np.concatenate([p0, f.direction * (LINE_TOL / ANGLE_TOL)])


def _groups(faces: list[AxialFace]) -> list[list[AxialFace]]:
    """Faces whose axis lines coincide, connected components of 'within tolerance'."""
    if not faces:
        return []
    keys = np.array([_line_key(f) for f in faces])
    pairs = cKDTree(keys).query_pairs(LINE_TOL * math.sqrt(2.0), output_type="ndarray")
    n = len(faces)
    graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
    _, labels = connected_components(graph, directed=False)
    out: dict[int, list[AxialFace]] = {}
    for f, lab in zip(faces, labels, strict=True):
        out.setdefault(int(lab), []).append(f)
    return list(out.values())


def _on_axis(f: AxialFace, origin: np.ndarray, direction: np.ndarray) -> tuple[float, float]:
    """``f``'s interval on the axis (origin, direction)."""
    shift = float(np.dot(f.origin - origin, direction))
    same = 1.0 if np.dot(f.direction, direction) > 0 else -1.0
    a, b = (shift + same * f.t_range[0], shift + same * f.t_range[1])
    return (min(a, b), max(a, b))


Interval = tuple[float, float]


def _runs(items: list[tuple[Interval, object]]) -> list[list[tuple[Interval, object]]]:
    """Items sorted by interval start, split where the intervals stop touching."""
    items = sorted(items, key=lambda it: it[0][0])
    runs: list[list[tuple[Interval, object]]] = []
    end = -math.inf
    for it in items:
        if runs and it[0][0] <= end + TOUCH_TOL:
            runs[-1].append(it)
            end = max(end, it[0][1])
        else:
            runs.append([it])
            end = it[0][1]
    return runs


def chains(faces: list[AxialFace]) -> tuple[list[Chain], list[Bore]]:
    """The hole chains among ``faces`` and the partial bores left out (fillets, slots)."""
    found: list[Chain] = []
    partial: list[Bore] = []
    inner = [f for f in faces if f.internal]
    for group in _groups(inner):
        direction = group[0].direction
        origin = group[0].origin - np.dot(group[0].origin, direction) * direction
        bores: list[tuple[Interval, object]] = []
        cyl = [f for f in group if f.kind == "cylinder"]
        for radius_group in _by_radius(cyl):
            for run in _runs([(_on_axis(f, origin, direction), f) for f in radius_group]):
                fs = [f for _, f in run]
                t = (min(r[0] for r, _ in run), max(r[1] for r, _ in run))
                bore = Bore(
                    fs[0].radius, t, fs, covered_angle([f.u_range for f in fs]) > 2 * math.pi - 1e-6
                )
                if bore.full:
                    bores.append((t, bore))
                else:
                    partial.append(bore)
        cones = [(_on_axis(f, origin, direction), f) for f in group if f.kind == "cone"]
        for run in _runs(bores + cones):
            chain_bores = [b for _, b in run if isinstance(b, Bore)]
            if chain_bores:
                found.append(
                    Chain(
                        origin,
                        direction,
                        sorted(chain_bores, key=lambda b: b.t_range[0]),
                        [(t, f) for t, f in run if isinstance(f, AxialFace)],
                    )
                )
    return found, partial


def _by_radius(faces: list[AxialFace]) -> list[list[AxialFace]]:
    out: list[list[AxialFace]] = []
    for f in sorted(faces, key=lambda f: f.radius):
        if out and abs(out[-1][0].radius - f.radius) <= RADIUS_TOL:
            out[-1].append(f)
        else:
            out.append([f])
    return out
