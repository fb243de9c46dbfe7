"""Speed benchmark of the stereo hole measurement, end to end, one core.

Full-frame 2448 × 2048 8-bit pairs of the standard scene (holes of 6, 10 and 19.4 mm,
tilts 0–30°) are rendered first; then ``measure_hole`` runs on each pair from the two raw
images to the fitted circle, OpenCV limited to one thread. Prints the median and 90th
percentile per stage and in total. Target: ≤ 30 ms per 5-megapixel pair (median).

Run: ``.venv/bin/python benchmarks/measure_speed.py`` (about 30 s) or ``--quick``.
"""

from __future__ import annotations

import argparse
import sys
import time

import cv2
import numpy as np

from measure import measure_hole
from measure.synth import RenderOptions, hole_in_view, render_hole_pair, standard_stereo

TARGET_S = 0.030
STAGES = ("detect", "edges", "match", "fit")


def main(argv: list[str] | None = None) -> int:
    """Run the benchmark; exit code 1 when the median misses the target."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="fewer scenes and repeats")
    args = ap.parse_args(argv)
    cv2.setNumThreads(1)
    scenes, repeats = (6, 3) if args.quick else (18, 5)
    stereo = standard_stereo()
    pairs = []
    t0 = time.perf_counter()
    for i in range(scenes):
        d = (0.006, 0.010, 0.0194)[i % 3]
        tilt = (0.0, 15.0, 30.0)[(i // 3) % 3]
        c, n = hole_in_view(stereo, np.deg2rad(tilt), 0.7 * i)
        r = render_hole_pair(stereo, c, n, d, RenderOptions(), seed=i)
        pairs.append((d, r))
    render_s = (time.perf_counter() - t0) / scenes
    for _, r in pairs[:2]:  # warm-up: imports, caches
        measure_hole(r.left, r.right, stereo)
    rows: dict[float, list[dict[str, float]]] = {}
    for _ in range(repeats):
        for d, r in pairs:
            m = measure_hole(r.left, r.right, stereo)
            rows.setdefault(d, []).append({**m.timings, "total": m.time_s})
    print(f"measure speed: {stereo.image_size[0]}x{stereo.image_size[1]} 8-bit pairs, one core,")
    print(f"{scenes} scenes x {repeats} runs (rendering took {render_s:.2f} s per pair)")
    head = "".join(f"{s:>10}" for s in (*STAGES, "total"))
    print(f"{'hole':<12}{'':<8}{head}   (ms)")
    everything = []
    for d, runs in rows.items():
        for stat, fn in (("median", np.median), ("p90", lambda a: np.percentile(a, 90))):
            vals = "".join(f"{fn([r[s] for r in runs]) * 1e3:>10.1f}" for s in (*STAGES, "total"))
            print(f"⌀{d * 1e3:<5g} mm  {stat:<8}{vals}")
        everything += runs
    total = np.median([r["total"] for r in everything])
    ok = total <= TARGET_S
    print(
        f"all pairs median total {total * 1e3:.1f} ms: {'PASS' if ok else 'FAIL'} (target ≤ 30 ms)"
    )
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
