"""Fit the built-in arms' collision primitives to the ROS-Industrial collision meshes.

Usage: ``python benchmarks/fit_link_shapes.py ABB_EXPERIMENTAL_CHECKOUT [--write]``

Per link, the mesh is cut into 1 to 3 slabs along one of the link frame's axes (cut positions
on a 5 % grid of the link's extent); each slab gets the smallest of an axis-aligned box and
a cylinder along x, y or z that holds every vertex of the slab (the cut polygons included), so
the union of the primitives encloses the mesh exactly, not only at sampled points. The cut
set with the least total volume wins, each extra primitive charged 4 % of the link's hull
volume plus 0.5 L, a tenth of that for a cylinder about a joint axis through the link (the
rounded end of a link about its joint, as ABB's castings are). Coaxial neighbours merge. Every
primitive is then grown by 1 mm and rounded outward to whole millimetres.

Prints the figures; ``--write`` rewrites ``robots/arm_shapes.py`` (the figures the URDF writer
uses) and ``tests/robots/data/rosi_link_points.json`` (per link, the mesh's extreme points
along 26 directions and its 8 points closest to leaving the primitives: what the enclosure
test checks without the meshes).
"""

from __future__ import annotations

import itertools
import json
import math
import sys
from pathlib import Path

import coal
import numpy as np
import trimesh
from scipy.spatial import ConvexHull

from robots.models import JOINT_AXES, LINK_NAMES, MODELS, ArmSpec
from rosi_meshes import (
    ROSI_MODELS,
    checkout_or_exit,
    load_link_meshes,
    signed_distance,
    surface_points,
)

REPO = Path(__file__).resolve().parent.parent
GRID = np.linspace(0.0, 1.0, 21)
MARGIN_M = 0.001
MM = 0.001
#: rotation taking a cylinder's local z onto the link axis (the URDF writer's rpy)
AXIS_R = {
    "x": np.array([[0.0, 0, 1], [0, 1, 0], [-1, 0, 0]]),
    "y": np.array([[1.0, 0, 0], [0, 0, 1], [0, -1, 0]]),
    "z": np.eye(3),
}


def _circle(points: np.ndarray) -> tuple[np.ndarray, float]:
    """Smallest circle holding 2-D ``points`` (Welzl, iterative): centre and radius."""
    rng = np.random.default_rng(0)
    pts = points[rng.permutation(len(points))]

    def two(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, float]:
        c = 0.5 * (a + b)
        return c, float(np.linalg.norm(a - c))

    def three(a: np.ndarray, b: np.ndarray, c: np.ndarray) -> tuple[np.ndarray, float]:
        d = 2 * (a[0] * (b[1] - c[1]) + b[0] * (c[1] - a[1]) + c[0] * (a[1] - b[1]))
        if abs(d) < 1e-15:
            cands = [two(a, b), two(a, c), two(b, c)]
            return max(cands, key=lambda t: t[1])
        sa, sb, sc = a @ a, b @ b, c @ c
        ux = (sa * (b[1] - c[1]) + sb * (c[1] - a[1]) + sc * (a[1] - b[1])) / d
        uy = (sa * (c[0] - b[0]) + sb * (a[0] - c[0]) + sc * (b[0] - a[0])) / d
        u = np.array([ux, uy])
        return u, float(np.linalg.norm(a - u))

    def inside(c: np.ndarray, r: float, p: np.ndarray) -> bool:
        return float(np.linalg.norm(p - c)) <= r + 1e-12

    c, r = pts[0], 0.0
    for i in range(1, len(pts)):
        if inside(c, r, pts[i]):
            continue
        c, r = pts[i], 0.0
        for j in range(i):
            if inside(c, r, pts[j]):
                continue
            c, r = two(pts[i], pts[j])
            for k in range(j):
                if not inside(c, r, pts[k]):
                    c, r = three(pts[i], pts[j], pts[k])
    return c, r


def _hull2d(p: np.ndarray) -> np.ndarray:
    try:
        return p[ConvexHull(p).vertices]
    except Exception:  # degenerate (collinear) slab: every point
        return p


def _clipped_area(c: float, r: float, lo: float, hi: float) -> float:
    """Area of a circle (centre ``c``, radius ``r`` along one coordinate) between lo and hi."""

    def below(t: float) -> float:
        d = min(max((t - c) / r, -1.0), 1.0) if r > 0 else float(np.sign(t - c))
        return r**2 * (0.5 * math.pi + math.asin(d) + d * math.sqrt(1.0 - d * d))

    return below(hi) - below(lo)


def _cylinder(
    v: np.ndarray, axis: int, c: np.ndarray, r: float, cut_axis: int, extent: tuple[float, float]
) -> dict:
    lo, hi = v.min(axis=0), v.max(axis=0)
    other = [k for k in range(3) if k != axis]
    length = hi[axis] - lo[axis]
    if cut_axis == axis:
        volume = math.pi * r**2 * length
    else:  # inside the slab, plus what sticks out past the link's ends (neighbours cover the rest)
        u = other.index(cut_axis)
        area = _clipped_area(c[u], r, lo[cut_axis], hi[cut_axis])
        area += _clipped_area(c[u], r, -np.inf, extent[0]) + _clipped_area(
            c[u], r, extent[1], np.inf
        )
        volume = area * length
    return {"kind": "cylinder", "axis": axis, "c": c, "r": r, "lo": lo, "hi": hi, "volume": volume}


def fit_piece(
    v: np.ndarray, cut_axis: int, extent: tuple[float, float], pivots: list[tuple[np.ndarray, int]]
) -> dict:
    """The cheapest box or cylinder holding the vertices ``v`` (link frame, m) of one slab.

    Candidates: the axis-aligned box; per axis, the cylinder on the smallest enclosing
    circle; per joint axis through the link (``pivots``: point, axis index), the cylinder
    about that joint axis. Cost: the volume inside the slab (a cylinder across the slab
    counts its circular segment only, plus any part beyond the link's ``extent`` along the
    cut axis: a rounded link end about its joint axis).
    """
    lo, hi = v.min(axis=0), v.max(axis=0)
    best = {"kind": "box", "lo": lo, "hi": hi, "volume": float(np.prod(hi - lo))}
    candidates = []
    for axis in range(3):
        other = [k for k in range(3) if k != axis]
        c, r = _circle(_hull2d(v[:, other]))
        candidates.append(_cylinder(v, axis, c, r, cut_axis, extent))
    for point, axis in pivots:
        other = [k for k in range(3) if k != axis]
        c = point[other]
        r = float(np.max(np.linalg.norm(v[:, other] - c, axis=1)))
        candidates.append({**_cylinder(v, axis, c, r, cut_axis, extent), "pivot": True})
    for cand in candidates:
        if cand["volume"] < best["volume"]:
            best = cand
    return best


def _slab(mesh: trimesh.Trimesh, axis: int, lo: float, hi: float) -> np.ndarray | None:
    """Vertices of the mesh clipped to ``lo <= x[axis] <= hi``: the vertices inside and the
    points where edges cross either plane (every corner of the clipped surface)."""
    v = np.asarray(mesh.vertices)
    x = v[:, axis]
    out = [v[(x >= lo) & (x <= hi)]]
    e = np.asarray(mesh.edges_unique)
    a, b = v[e[:, 0]], v[e[:, 1]]
    xa, xb = a[:, axis], b[:, axis]
    for plane in (lo, hi):
        cross = (xa - plane) * (xb - plane) < 0
        t = (plane - xa[cross]) / (xb[cross] - xa[cross])
        out.append(a[cross] + t[:, None] * (b[cross] - a[cross]))
    pts = np.vstack(out)
    return pts if len(pts) >= 4 else None


def fit_link(mesh: trimesh.Trimesh, pivots: list[tuple[np.ndarray, int]]) -> list[dict]:
    """The cheapest cover of one link mesh: 1 to 3 slabs, each a box or a cylinder.

    ``pivots`` are the joint axes through the link (point in the link frame, axis index);
    their positions are cut candidates too, so a slab can end on a joint axis.
    """
    hull_volume = float(mesh.convex_hull.volume)
    penalty = 0.04 * hull_volume + 0.0005
    best: tuple[float, list[dict]] | None = None
    for axis in range(3):
        lo, hi = mesh.bounds[0][axis], mesh.bounds[1][axis]
        at_joints = [p[axis] for p, _ in pivots if lo < p[axis] < hi]
        cuts = np.unique(np.r_[lo + GRID * (hi - lo), at_joints])
        cache: dict[tuple[int, int], dict | None] = {}
        for i, j in itertools.combinations(range(len(cuts)), 2):
            v = _slab(mesh, axis, cuts[i] - 1e-9, cuts[j] + 1e-9)
            cache[(i, j)] = None if v is None else fit_piece(v, axis, (lo, hi), pivots)

        n = len(cuts) - 1
        for k in (0, 1, 2):
            for inner in itertools.combinations(range(1, n), k):
                bounds = (0, *inner, n)
                pieces = [cache[(a, b)] for a, b in itertools.pairwise(bounds)]
                pieces = [p for p in pieces if p is not None]
                # a rounded end about a joint axis is what ABB links look like: a tenth of it
                extra = sum(0.1 if p.get("pivot", False) else 1.0 for p in pieces)
                cost = sum(p["volume"] for p in pieces) + penalty * extra
                if best is None or cost < best[0]:
                    best = (cost, pieces)
    assert best is not None
    return best[1]


def merge_coaxial(pieces: list[dict], tol_m: float = 0.003) -> list[dict]:
    """Neighbouring slabs that both got a cylinder about (nearly) the same axis line become one
    cylinder holding both (radius grown by the centre offset)."""
    out: list[dict] = []
    for p in pieces:
        for q in out:
            same = p["kind"] == q["kind"] == "cylinder" and p["axis"] == q["axis"]
            if same and float(np.linalg.norm(p["c"] - q["c"])) <= tol_m:
                q["r"] = max(q["r"], p["r"] + float(np.linalg.norm(p["c"] - q["c"])))
                q["lo"], q["hi"] = np.minimum(q["lo"], p["lo"]), np.maximum(q["hi"], p["hi"])
                break
        else:
            out.append(dict(p))
    return out


def joint_pivots(spec: ArmSpec, link: str) -> list[tuple[np.ndarray, int]]:
    """The joint axes through ``link`` (its own joint at the origin, the next joint at its
    origin), as (point in the link frame (m), axis index)."""
    k = LINK_NAMES.index(link)
    pivots = []
    if k >= 1:
        pivots.append((np.zeros(3), "xyz".index(JOINT_AXES[k - 1])))
    if k < len(JOINT_AXES):
        pivots.append((np.asarray(spec.joint_origins_m[k], float), "xyz".index(JOINT_AXES[k])))
    return pivots


def _floor(x: float) -> float:
    return math.floor(round(x / MM, 6)) * MM


def _ceil(x: float) -> float:
    return math.ceil(round(x / MM, 6)) * MM


def rounded(piece: dict) -> dict:
    """The piece grown by :data:`MARGIN_M` and rounded outward to whole mm (link frame)."""
    lo = [_floor(x - MARGIN_M) for x in piece["lo"]]
    hi = [_ceil(x + MARGIN_M) for x in piece["hi"]]
    if piece["kind"] == "box":
        size = tuple(round(b - a, 6) for a, b in zip(lo, hi, strict=True))
        xyz = tuple(round(0.5 * (a + b), 6) for a, b in zip(lo, hi, strict=True))
        return {"kind": "box", "size": size, "xyz": xyz, "axis": "z"}
    axis = piece["axis"]
    other = [k for k in range(3) if k != axis]
    c = [round(x / MM) * MM for x in piece["c"]]
    shift = float(np.linalg.norm(np.array(c) - piece["c"]))
    radius = _ceil(piece["r"] + shift + MARGIN_M)
    xyz = [0.0, 0.0, 0.0]
    xyz[other[0]], xyz[other[1]] = c
    xyz[axis] = 0.5 * (lo[axis] + hi[axis])
    length = hi[axis] - lo[axis]
    return {
        "kind": "cylinder",
        "size": (round(radius, 6), round(length, 6)),
        "xyz": tuple(round(x, 6) for x in xyz),
        "axis": "xyz"[axis],
    }


def test_points(mesh: trimesh.Trimesh, worst: np.ndarray) -> list[list[float]]:
    """Extreme points of the mesh along 26 directions plus the given worst points (m)."""
    dirs = [np.array(d, float) for d in itertools.product((-1, 0, 1), repeat=3) if any(d)]
    v = np.asarray(mesh.vertices)
    pts = [v[int(np.argmax(v @ d))] for d in dirs] + list(worst)
    return [[round(float(x), 6) for x in p] for p in pts]


def _module_text(figures: dict[str, list[tuple[str, dict]]]) -> str:
    lines = [
        '"""Collision primitives of the built-in arms, per link in the link frame (m).',
        "",
        "Written by ``benchmarks/fit_link_shapes.py`` from the ROS-Industrial collision meshes",
        "of the same arms (``ros-industrial/abb_experimental``, Apache-2.0; no mesh is kept",
        "here): each link's primitives enclose its mesh with at least 1 mm to spare.",
        "``tests/robots/test_robots_enclosure.py`` checks them against points measured on the",
        "meshes. Sizes: box (x, y, z) edge lengths; cylinder (radius, length) along ``axis``.",
        '"""',
        "",
        "from __future__ import annotations",
        "",
        "#: (link, kind, size, xyz of the centre in the link frame, cylinder axis)",
        "Primitive = tuple[str, str, tuple[float, ...], tuple[float, float, float], str]",
        "",
        "#: model -> its primitives, link by link",
        "LINK_PRIMITIVES: dict[str, tuple[Primitive, ...]] = {",
    ]
    for model, rows in figures.items():
        lines.append(f'    "{model}": (')
        for link, r in rows:
            size = ", ".join(f"{x:g}" for x in r["size"]) + ("," if len(r["size"]) == 1 else "")
            xyz = ", ".join(f"{x:g}" for x in r["xyz"])
            lines.append(f'        ("{link}", "{r["kind"]}", ({size}), ({xyz}), "{r["axis"]}"),')
        lines.append("    ),")
    lines.append("}")
    return "\n".join(lines) + "\n"


def _points_json(points: dict[str, dict[str, list[list[float]]]]) -> str:
    """The test figures as JSON, one point per line."""
    models = []
    for model, links in points.items():
        rows = []
        for link, pts in links.items():
            body = ",\n".join(f"      {json.dumps(p)}" for p in pts)
            rows.append(f'    "{link}": [\n{body}\n    ]')
        models.append(f'  "{model}": {{\n' + ",\n".join(rows) + "\n  }")
    return "{\n" + ",\n".join(models) + "\n}\n"


def main() -> None:
    root = checkout_or_exit(sys.argv, "fit_link_shapes.py ABB_EXPERIMENTAL_CHECKOUT [--write]")
    figures: dict[str, list[tuple[str, dict]]] = {}
    points: dict[str, dict[str, list[list[float]]]] = {}
    for model in ROSI_MODELS:
        meshes = load_link_meshes(root, model)
        spec = MODELS[model]
        figures[model], points[model] = [], {}
        print(f"{model}")
        for link, mesh in meshes.items():
            rows = [rounded(p) for p in merge_coaxial(fit_link(mesh, joint_pivots(spec, link)))]
            figures[model] += [(link, r) for r in rows]
            prims = []
            for r in rows:
                T = np.eye(4)
                T[:3, 3] = r["xyz"]
                if r["kind"] == "box":
                    prims.append((coal.Box(*r["size"]), T))
                else:
                    T[:3, :3] = AXIS_R[r["axis"]]
                    prims.append((coal.Cylinder(*r["size"]), T))
            pts = surface_points(mesh)
            sd = np.min([signed_distance(g, (pts - T[:3, 3]) @ T[:3, :3]) for g, T in prims], 0)
            out, inner = np.maximum(sd, 0.0), -sd
            worst = pts[np.argsort(inner)[:8]]
            points[model][link] = test_points(mesh, worst)
            for r in rows:
                print(f"  {link:9s} {r['kind']:8s} {r['axis']} size {r['size']} at {r['xyz']}")
            print(
                f"  {link:9s} protrusion {out.max() * 1e3:.2f} mm, least margin "
                f"{inner.min() * 1e3:.2f} mm"
            )
    if "--write" in sys.argv:
        (REPO / "robots" / "arm_shapes.py").write_text(_module_text(figures))
        data = REPO / "tests" / "robots" / "data"
        data.mkdir(parents=True, exist_ok=True)
        (data / "rosi_link_points.json").write_text(_points_json(points))
        print("written robots/arm_shapes.py, tests/robots/data/rosi_link_points.json")


if __name__ == "__main__":
    main()
