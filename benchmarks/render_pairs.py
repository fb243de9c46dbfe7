"""CPU per rendered stereo pair of the simulated head, before and after (issue 27), by kind.

The demo renders three kinds of 5 MP pairs (2448 × 2048, both cameras of the standard head):

- calibration: the cell's chessboard plate (9 × 6, 9 mm) at 0.2–0.35 m, tilted up to 35°
  (:func:`measure.synth.targets.render_target_pair`);
- survey: ring markers of 5 and 10 mm at 0.3–1.2 m over a dim background
  (:func:`measure.synth.render_markers_pair`);
- run: a hole (6–12 mm, some as reference bores) at 0.25 m with up to 5 markers of 5 mm around
  it (:func:`measure.synth.render_hole_pair` / ``render_reference_pair``).

Each version of the renderer runs in a child process over the same scenes (seeded), after one
warm-up pair of each kind (Numba's compilation, the cached rays, texture and noise bank are
per process, not per pair), printing the CPU time (``time.process_time``) per pair and a digest
of every image. The baseline is the renderer at ``--baseline`` (a git revision; default: main
before the issue-27 render work), taken with ``git archive`` into a temporary folder; the two
versions run alternately ``--rounds`` times and the median per kind is printed, with the
machine's load. "identical" counts the pairs whose images are the same bytes in both versions.

Run: ``PYTHONPATH=. python benchmarks/render_pairs.py [--pairs 8] [--rounds 2]``.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

#: main before issue 27's render work (the renderer the demo's profile measured)
BASELINE_REV = "0ffceb6"
KINDS = ("calibration", "survey", "run")
ROOT = Path(__file__).resolve().parent.parent


def _scenes(kind: str, n: int):
    """``n`` callables rendering a pair of ``kind`` (seeded, the same in every version)."""
    from scipy.spatial.transform import Rotation

    from measure.markers.design import DEFAULT_DESIGN
    from measure.synth import (
        RenderOptions,
        hole_in_view,
        render_hole_pair,
        render_markers_pair,
        render_reference_pair,
        standard_stereo,
    )
    from measure.synth.marker_scenes import marker_grid_view
    from measure.synth.targets import render_target_pair
    from measure.target import TargetSpec

    st = standard_stereo()
    rng = np.random.default_rng({"calibration": 1, "survey": 2, "run": 3}[kind])
    out = []
    if kind == "calibration":
        spec = TargetSpec("chessboard", 9, 6, 0.009)
        w, h = st.image_size
        pts = spec.object_points()
        centre = 0.5 * (pts.min(axis=0) + pts.max(axis=0))
        while len(out) < n:
            T = np.eye(4)
            axis = rng.normal(size=3) * [1, 1, 0]
            R = Rotation.from_rotvec(rng.uniform(0, np.radians(35)) * axis / np.linalg.norm(axis))
            T[:3, :3] = (R * Rotation.from_euler("z", rng.uniform(-0.5, 0.5))).as_matrix()
            aim = np.array([rng.uniform(-0.02, 0.07), rng.uniform(-0.03, 0.03), 1.0])
            T[:3, 3] = aim * rng.uniform(0.2, 0.35) - T[:3, :3] @ centre
            X = pts @ T[:3, :3].T + T[:3, 3]
            if all(np.all((st.project(X, s) > 20) & (st.project(X, s) < [w - 20, h - 20]))
                   for s in ("left", "right")):  # fmt: skip
                seed = len(out)
                out.append(lambda T=T, seed=seed: render_target_pair(st, spec, T, seed=seed))
    elif kind == "survey":
        opts = RenderOptions()
        for i in range(n):
            markers = []
            for d, standoff in ((0.010, rng.uniform(0.5, 1.2)), (0.005, rng.uniform(0.3, 0.6))):
                markers += marker_grid_view(st, rng, DEFAULT_DESIGN, d, standoff, 50.0)
            out.append(lambda m=markers, i=i: render_markers_pair(st, m, opts, seed=i))
    else:
        opts = RenderOptions()
        for i in range(n):
            c, nrm = hole_in_view(st, rng.uniform(0, np.radians(30)), rng.uniform(0, 2 * np.pi))
            d = rng.uniform(0.006, 0.012)
            k = int(rng.integers(1, 6))
            markers = marker_grid_view(st, rng, DEFAULT_DESIGN, 0.005, 0.26, 20.0, max_markers=9)
            markers = [m for j, m in enumerate(markers) if j != 4][:k]  # not over the hole
            fn = render_reference_pair if i % 4 == 3 else render_hole_pair
            out.append(lambda fn=fn, c=c, nrm=nrm, d=d, m=markers, i=i: fn(st, c, nrm, d, opts, i,
                                                                           markers=m))  # fmt: skip
    return out


def child(n: int) -> None:
    """Render every kind's scenes; print JSON: CPU ms per pair and image digests."""
    res = {}
    for kind in KINDS:
        scenes = _scenes(kind, n + 1)
        scenes[0]()  # warm-up: compilation, per-process caches
        cpu, digests = [], []
        for fn in scenes[1:]:
            c = time.process_time()
            pair = fn()
            cpu.append(1e3 * (time.process_time() - c))
            digests.append(hashlib.sha1(pair.left.tobytes() + pair.right.tobytes()).hexdigest())
        res[kind] = {"cpu_ms": cpu, "digests": digests}
    print(json.dumps(res))


def _run(code_dir: Path | None, n: int) -> dict:
    env = dict(os.environ)
    paths = [str(code_dir)] if code_dir else []  # the baseline's measure/ wins over ours
    env["PYTHONPATH"] = os.pathsep.join([*paths, str(ROOT), env.get("PYTHONPATH", "")])
    cmd = [sys.executable, str(Path(__file__).resolve()), "--child", "--pairs", str(n)]
    out = subprocess.run(cmd, env=env, capture_output=True, text=True, check=True, cwd=ROOT)
    return json.loads(out.stdout.strip().splitlines()[-1])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--pairs", type=int, default=8, help="pairs per kind (after one warm-up)")
    ap.add_argument("--rounds", type=int, default=2, help="alternating runs of each version")
    ap.add_argument("--baseline", default=BASELINE_REV, help="git revision of the 'before'")
    ap.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.child:
        child(args.pairs)
        return
    load0 = os.getloadavg()[0]
    with tempfile.TemporaryDirectory() as tmp:
        archive = subprocess.run(["git", "archive", args.baseline, "measure"], cwd=ROOT,
                                 capture_output=True)  # fmt: skip
        runs: dict[str, list[dict]] = {"before": [], "after": []}
        if archive.returncode == 0:
            subprocess.run(["tar", "-x", "-C", tmp], input=archive.stdout, check=True)
        else:  # e.g. a shallow clone: the current renderer alone
            print(f"(no baseline: git archive {args.baseline} failed; 'before' = this tree)")
            tmp = None
        for _ in range(args.rounds):
            runs["before"].append(_run(Path(tmp) if tmp else None, args.pairs))
            runs["after"].append(_run(None, args.pairs))
    load1 = os.getloadavg()[0]
    print(f"CPU per 5 MP stereo pair (ms; median over {args.pairs} pairs x {args.rounds} "
          f"alternating runs per version; before = {args.baseline}); load average "
          f"{load0:.1f} -> {load1:.1f} on {os.cpu_count()} cores")  # fmt: skip
    print("| kind        | before ms | after ms | speed-up | identical images |")
    print("|-------------|-----------|----------|----------|------------------|")
    for kind in KINDS:
        b = np.median(np.concatenate([r[kind]["cpu_ms"] for r in runs["before"]]))
        a = np.median(np.concatenate([r[kind]["cpu_ms"] for r in runs["after"]]))
        old, new = runs["before"][0][kind]["digests"], runs["after"][0][kind]["digests"]
        same = sum(x == y for x, y in zip(old, new, strict=True))
        n = args.pairs
        print(f"| {kind:<11} | {b:9.1f} | {a:8.1f} | {b / a:7.1f}x | {same:>7d} of {n:<5d} |")


if __name__ == "__main__":
    main()
