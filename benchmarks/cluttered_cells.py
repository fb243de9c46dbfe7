"""Generator of the cluttered benchmark cells: parts on fixture columns among posts and plates.

Each cell is the built-in cell's robot (IRB 2600), stereo head and home pose in front
of a table that carries 2–4 parts (box-shaped brackets and plates of random size and
yaw, each on two fixture columns, so their undersides are clear) with, between and in
front of them, posts (vertical cylinders), guard plates (thin vertical boxes) and
clamps. Holes lie on every face of the parts: the top, the face toward the robot, the
sides, the back (reachable only by reaching over or around the part) and the underside
(reachable only from below, between the columns), each normal tilted by up to 15° as
on a chamfered boss. Everything is seeded: the same (holes, parts, seed) gives the
same file. Units: m, rad; part frame = cell frame.

Usage: ``python benchmarks/cluttered_cells.py [--out benchmarks/cells]`` writes the
benchmark family (``cluttered-20``, ``-40``, ``-80`` and ``-250``);
``--variants N [--variant-of 40] --out DIR`` writes N variants of one product (the
same parts and holes, fixture positions and clutter re-drawn) for the batch benchmark.
"""

from __future__ import annotations

import argparse
import itertools
import sys
from pathlib import Path

import numpy as np
import yaml

from cell.config import HoleInCell, builtin_cell_path, parse_cell
from cell.config.datums import without_drawing
from planner.viewpoints import hole_candidates
from robots.transforms import matrix_to_rpy

#: (holes, parts, seed) of the benchmark family
FAMILY = ((20, 2, 1020), (40, 3, 1040), (80, 4, 1080), (250, 4, 1250))
TABLE_TOP_Z = 0.25
#: face name -> (outward normal in the part's own frame, share of the holes)
#: and the bias added to the face normal (cell frame) before normalising: holes on the back
#: lean up (reached over the part), on the underside toward the robot (reached from below),
#: on the sides toward the robot and up (the gaps between parts are narrower than the standoff)
FACES = {
    "top": ((0, 0, 1), 0.30, (0, 0, 0)),
    "front": ((-1, 0, 0), 0.25, (0, 0, 0)),
    "left": ((0, 1, 0), 0.10, (-0.7, 0, 0.5)),
    "right": ((0, -1, 0), 0.10, (-0.7, 0, 0.5)),
    "back": ((1, 0, 0), 0.15, (0, 0, 2.0)),
    "bottom": ((0, 0, -1), 0.10, (-1.3, 0, 0)),
}


def _pose(xyz: np.ndarray, R: np.ndarray) -> dict:
    return {"xyz": [round(float(v), 5) for v in xyz], "rpy": [float(v) for v in matrix_to_rpy(R)]}


def _rz(yaw: float) -> np.ndarray:
    c, s = np.cos(yaw), np.sin(yaw)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _tilt(n: np.ndarray, rng: np.random.Generator, max_rad: float) -> np.ndarray:
    """``n`` tilted by a random angle up to ``max_rad`` in a random direction (unit)."""
    ref = np.array([1.0, 0, 0]) if abs(n[0]) < 0.9 else np.array([0, 1.0, 0])
    u = np.cross(n, ref)
    u /= np.linalg.norm(u)
    v = np.cross(n, u)
    phi, th = rng.uniform(0, 2 * np.pi), rng.uniform(0, max_rad)
    m = np.cos(th) * n + np.sin(th) * (np.cos(phi) * u + np.sin(phi) * v)
    return m / np.linalg.norm(m)


def _part(rng: np.random.Generator, y_c: float, width: float) -> tuple[np.ndarray, ...]:
    """One part: centre (m), rotation, full size (m)."""
    size = np.array(
        [rng.uniform(0.12, 0.28), rng.uniform(0.6, 0.9) * width, rng.uniform(0.05, 0.14)]
    )
    z = TABLE_TOP_Z + rng.uniform(0.28, 0.42) + size[2] / 2
    centre = np.array([rng.uniform(0.85, 1.0), y_c, z])
    return centre, _rz(rng.uniform(-0.35, 0.35)), size


def _hole_stream(rng, parts, prefix: str = "P"):
    """Endless stream of holes on the parts' faces, parts in turn."""
    names = list(FACES)
    shares = np.array([FACES[f][1] for f in names])
    for k in itertools.count():
        p = k % len(parts)
        centre, R, size = parts[p]
        face = names[int(rng.choice(len(names), p=shares / shares.sum()))]
        n_local = np.array(FACES[face][0], dtype=float)
        axis = int(np.argmax(np.abs(n_local)))
        local = rng.uniform(-0.5, 0.5, 3) * np.maximum(size - 0.04, 0.01)
        local[axis] = n_local[axis] * size[axis] / 2
        n = R @ n_local + np.array(FACES[face][2], dtype=float)
        n = _tilt(n / np.linalg.norm(n), rng, np.radians(15))
        yield (
            {
                "id": f"{prefix}{p + 1}-{face[:2].upper()}{k + 1:03d}",
                "position": [round(float(v), 5) for v in centre + R @ local],
                "normal": [round(float(v), 6) for v in n],
                "diameter": round(float(rng.choice([0.006, 0.008, 0.01, 0.012, 0.016])), 4),
                "tolerance": 5.0e-05,
            }
        )


def _select_holes(data: dict, stream, n_holes: int) -> list[dict]:
    """``n_holes`` reachable holes from ``stream`` (the planner's own viewpoint test) and the
    unreachable ones met on the way, up to 10 % of ``n_holes`` (they exercise the left-out path)."""
    data = dict(data, part=dict(data["part"], holes=[]))
    arm = parse_cell(yaml.safe_dump(_plain(data)), "<generated>").build_arm()
    standoff = data["tool"]["standoff_m"]
    kept, reachable, unreachable = [], 0, 0
    for h in stream:
        hole = HoleInCell(
            h["id"], np.array(h["position"]), np.array(h["normal"]), h["diameter"], None
        )
        ok = hole_candidates(arm, hole, standoff, 15.0, 0.0, 1).ok
        if ok or unreachable < n_holes // 10:
            kept.append(h)
            reachable += ok
            unreachable += not ok
        if reachable == n_holes:
            return kept
    raise AssertionError("unreachable")


def _clutter(rng, parts, y_edges: np.ndarray) -> list[dict]:
    """Fixture columns under every part, posts and guard plates between and before them."""
    obs: list[dict] = []
    eye = np.eye(3)
    for p, (centre, R, size) in enumerate(parts):
        bottom = centre[2] - size[2] / 2
        h = bottom - TABLE_TOP_Z
        for side in (-1, 1):
            xy = centre + R @ np.array([0.0, side * size[1] * 0.3, 0.0])
            base = np.array([xy[0], xy[1], TABLE_TOP_Z + h / 2])
            cyl = {"radius": round(float(rng.uniform(0.015, 0.025)), 4), "length": round(h, 4)}
            obs.append(
                {"name": f"column_{p}_{side + 1}", "cylinder": cyl, "pose": _pose(base, eye)}
            )
        clamp = centre + R @ np.array([size[0] * rng.uniform(-0.4, 0.4), 0, size[2] / 2 + 0.02])
        box = {"size": [0.04, 0.05, 0.04]}
        obs.append({"name": f"clamp_{p}", "box": box, "pose": _pose(clamp, R)})
    for g, y in enumerate(y_edges[1:-1]):  # between neighbouring parts
        height = rng.uniform(0.45, 0.65)
        x = rng.uniform(0.85, 1.1)
        if rng.random() < 0.5:
            xyz = np.array([x, y, TABLE_TOP_Z + height / 2])
            cyl = {"radius": round(float(rng.uniform(0.02, 0.035)), 4), "length": round(height, 4)}
            obs.append({"name": f"post_{g}", "cylinder": cyl, "pose": _pose(xyz, eye)})
        else:
            size = [round(float(rng.uniform(0.15, 0.3)), 4), 0.01, round(height - 0.25, 4)]
            xyz = np.array([x, y, TABLE_TOP_Z + 0.25 + size[2] / 2])
            obs.append({"name": f"plate_{g}", "box": {"size": size}, "pose": _pose(xyz, eye)})
    for k in range(int(rng.integers(1, 3))):  # posts in front of the parts, toward the robot
        height = rng.uniform(0.5, 0.75)
        xyz = np.array(
            [
                rng.uniform(0.68, 0.75),
                rng.choice([-1, 1]) * rng.uniform(0.3, 0.55),
                TABLE_TOP_Z + height / 2,
            ]
        )
        cyl = {"radius": round(float(rng.uniform(0.015, 0.025)), 4), "length": round(height, 4)}
        obs.append({"name": f"front_post_{k}", "cylinder": cyl, "pose": _pose(xyz, eye)})
    table_xyz = np.array([1.08, 0.0, TABLE_TOP_Z / 2])
    table = {"size": [0.62, 1.5, TABLE_TOP_Z]}
    obs.append({"name": "table", "box": table, "pose": _pose(table_xyz, eye)})
    return obs


def cluttered_cell(n_holes: int, n_parts: int, seed: int, variant: int | None = None) -> dict:
    """The cell file contents (a mapping) of one cluttered instance (see module docstring).

    ``variant`` keeps the parts and holes of ``seed`` and re-draws the fixtures' positions
    along x and the clutter (a product family after a fixture change).
    """
    rng = np.random.default_rng(seed)
    data = yaml.safe_load(builtin_cell_path().read_text())
    y_edges = np.linspace(-0.62, 0.62, n_parts + 1)
    width = float(y_edges[1] - y_edges[0])
    parts = [_part(rng, float((a + b) / 2), width) for a, b in itertools.pairwise(y_edges)]
    stream = _hole_stream(rng, parts)
    crng = rng if variant is None else np.random.default_rng([seed, variant])
    shift = np.zeros(3)
    if variant is not None:  # the same parts and holes, shifted on the table together
        shift = np.array([crng.uniform(-0.06, 0.06), crng.uniform(-0.04, 0.04), 0.0])
        parts = [(c + shift, R, s) for c, R, s in parts]
    obstacles = []
    for p, (centre, R, size) in enumerate(parts):
        box = {"size": [round(float(v), 4) for v in size]}
        obstacles.append({"name": f"part_{p + 1}", "box": box, "pose": _pose(centre, R)})
    suffix = "" if variant is None else f"-v{variant:02d}"
    data["name"] = f"cluttered-{n_holes}{suffix}"
    data["part"] = {
        "base": {"xyz": [0, 0, 0], "rpy": [0, 0, 0]},
        "holes": [],
        "obstacles": obstacles,
    }
    data["environment"] = {"obstacles": _clutter(crng, parts, y_edges)}
    shifted = (
        dict(
            h, position=[round(float(v + d), 5) for v, d in zip(h["position"], shift, strict=True)]
        )
        for h in stream
    )
    data["part"]["holes"] = _select_holes(data, shifted, n_holes)
    without_drawing(data, 5e-5)  # the subset may leave datum features out
    data["reference_targets"] = [
        {"id": "R1", "position": [0.85, -0.68, TABLE_TOP_Z + 0.001], "normal": [0, 0, 1],
         "diameter": 0.01},
    ]  # fmt: skip
    return data


def _plain(x: object) -> object:
    """``x`` with numpy scalars turned into Python floats (for YAML)."""
    if isinstance(x, dict):
        return {k: _plain(v) for k, v in x.items()}
    if isinstance(x, list | tuple):
        return [_plain(v) for v in x]
    return float(x) if isinstance(x, np.floating) else x


def write(data: dict, path: Path, header: str) -> None:
    path.write_text(f"# {header}\n" + yaml.safe_dump(_plain(data), sort_keys=False))


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=Path(__file__).parent / "cells")
    ap.add_argument("--variants", type=int, default=0, help="write N variants of one instance")
    ap.add_argument("--variant-of", type=int, default=40, choices=[f[0] for f in FAMILY])
    args = ap.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    if args.variants:
        n, parts, seed = next(f for f in FAMILY if f[0] == args.variant_of)
        for v in range(args.variants):
            data = cluttered_cell(n, parts, seed, variant=v)
            head = f"generated by benchmarks/cluttered_cells.py --variants (seed {seed}, v {v})"
            write(data, args.out / f"{data['name']}.yaml", head)
        return 0
    for n, parts, seed in FAMILY:
        data = cluttered_cell(n, parts, seed)
        head = f"generated by benchmarks/cluttered_cells.py ({n} holes, {parts} parts, seed {seed})"
        write(data, args.out / f"{data['name']}.yaml", head)
        print(args.out / f"{data['name']}.yaml")
    return 0


if __name__ == "__main__":
    sys.exit(main())
