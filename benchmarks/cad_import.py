"""``holecell import-step`` on generated plates of 10 to 1000 holes (a third through, a third
blind, a third counterbored), and on STEP files given on the command line (public models: the
NIST MBE PMI test cases, docs/cad_import.md).

Per generated plate: the time to read the STEP, find the holes, read the PMI and tessellate
the mesh at 0.2 mm, and the largest error of every hole against the generating script
(entry centre, normal, diameter, depth). Per file given, a table row: holes found, through,
counterbored, the AP242 PMI kept (the datum frame, position and size tolerances), datums whose
faces came from the STEP entity graph, PMI listed as not modelled, times.

Usage: ``.venv/bin/python benchmarks/cad_import.py [--sizes 10 100 1000] [--mesh] [FILE.step ...]``
"""

from __future__ import annotations

import argparse
import math
import tempfile
import time
from pathlib import Path

import numpy as np
from build123d import Box, export_step

from cell.cad.part import import_step
from cell.config.step_part import drawing


def _plate(n: int, folder: Path):
    import sys

    sys.path.insert(0, str(Path(__file__).parents[1] / "tests" / "cad"))
    from cad_parts import _true, drill

    side = math.ceil(math.sqrt(n))
    pitch = 12.0
    size = side * pitch + 20
    part = Box(size, size, 10)
    tools, truth = [], []
    for k in range(n):
        x = -size / 2 + 10 + pitch * (k % side + 0.5)
        y = -size / 2 + 10 + pitch * (k // side + 0.5)
        kind = k % 3
        if kind == 0:
            tools.append(drill((x, y, 5), (0, 0, 1), 5.0, 12))
            truth.append(_true((x, y, 5), (0, 0, 1), 5.0, 10, True, (5.0,)))
        elif kind == 1:
            tools.append(drill((x, y, 5), (0, 0, 1), 4.0, 6.0))
            truth.append(_true((x, y, 5), (0, 0, 1), 4.0, 6.0, False, (4.0,)))
        else:
            tools.append(drill((x, y, 5), (0, 0, 1), 5.5, 12))
            tools.append(drill((x, y, 5), (0, 0, 1), 9.0, 4.0))
            truth.append(_true((x, y, 5), (0, 0, 1), 9.0, 10, True, (9.0, 5.5)))
    t0 = time.perf_counter()
    part = part - tools
    path = folder / f"plate_{n}.step"
    export_step(part, str(path))
    return path, truth, time.perf_counter() - t0


def _errors(found, truth) -> tuple[int, float, float, float, float]:
    """Holes matched, worst entry error (um), normal (deg), diameter (um), depth (um)."""
    pos = np.array([h.entry_m for h in found])
    worst = [0.0, 0.0, 0.0, 0.0]
    matched = 0
    for tr in truth:
        k = int(np.argmin(np.linalg.norm(pos - tr.entry_m, axis=1)))
        h = found[k]
        matched += 1
        worst[0] = max(worst[0], float(np.linalg.norm(pos[k] - tr.entry_m)) * 1e6)
        cos = float(np.clip(np.dot(h.normal, tr.normal), -1, 1))
        worst[1] = max(worst[1], math.degrees(math.acos(cos)))
        worst[2] = max(worst[2], abs(h.diameter_m - tr.diameter_m) * 1e6)
        worst[3] = max(worst[3], abs(h.depth_m - tr.depth_m) * 1e6)
    return matched, *worst  # type: ignore[return-value]


def _feature(d: dict) -> str:
    """``A=plane(8)``, ``B=H01``, ``G=pattern(2)``: a datum kept and its feature."""
    if "plane" in d:
        return f"{d['label']}=plane({len(d['plane']['holes'])})"
    if "pattern" in d:
        return f"{d['label']}=pattern({len(d['pattern'])})"
    return f"{d['label']}={d['hole']}"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("files", nargs="*", help="STEP files to import and report")
    ap.add_argument("--sizes", nargs="*", type=int, default=[10, 100, 1000])
    ap.add_argument("--mesh", action="store_true", help="also tessellate the files given")
    args = ap.parse_args()
    if args.sizes:
        print("| holes | faces | generate s | read s | holes s | PMI s | mesh s | total s |"
              " CPU s without mesh | entry um | normal deg | diameter um | depth um |")  # fmt: skip
        print("|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
        with tempfile.TemporaryDirectory() as tmp:
            for n in args.sizes:
                path, truth, t_gen = _plate(n, Path(tmp))
                cpu0 = time.process_time()
                import_step(path, mesh=False)
                cpu = time.process_time() - cpu0
                part = import_step(path)
                t = part.timings_s
                found = part.scan.holes
                assert len(found) == len(truth), (len(found), len(truth))
                _, e_pos, e_ang, e_d, e_depth = _errors(found, truth)
                from cell.cad.cylinders import face_map
                from cell.cad.step_read import read_step

                faces = face_map(read_step(path).shape).Extent()
                print(
                    f"| {n} | {faces} | {t_gen:.1f} | {t['read']:.2f} | {t['holes']:.2f} | "
                    f"{t['pmi']:.2f} | {t['mesh']:.2f} | {sum(t.values()):.2f} | {cpu:.2f} | "
                    f"{e_pos:.2g} | "
                    f"{e_ang:.2g} | {e_d:.2g} | {e_depth:.2g} |"
                )
    if args.files:
        print(
            "| model | schema | holes | through | stepped | datum frame kept | positions kept |"
            " sizes kept | datums via entity graph | listed | read + holes s | PMI s |"
        )
        print("|---|---|---:|---:|---:|---|---:|---:|---:|---:|---:|---:|")
    for f in args.files:
        part = import_step(f, mesh=args.mesh)
        holes = part.scan.holes
        datums, tols, left = drawing(part.pmi.datums, part.pmi.tolerances)
        t = part.timings_s
        if part.pmi.semantic:
            frame = " ".join(_feature(d) for d in datums)
            kept = (
                f"{frame or 'none'} | {sum('position' in v for v in tols.values())} | "
                f"{sum('size' in v for v in tols.values())} | "
                f"{sum('entity graph' in n for n in part.pmi.notes)} | "
                f"{len(part.pmi.unmodelled) + len(left)}"
            )
        else:
            kept = "no semantic PMI | | | | "
        print(
            f"| {Path(f).stem} | {part.schema.split('_')[0]} | {len(holes)} | "
            f"{sum(h.through for h in holes)} | {sum(len(h.bores) > 1 for h in holes)} | "
            f"{kept} | {t['read'] + t['holes']:.2f} | {t['pmi']:.2f} |"
        )


if __name__ == "__main__":
    main()
