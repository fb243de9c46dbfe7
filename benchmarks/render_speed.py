"""Calibration plate rendering: time per view and corner accuracy, old renderer vs new.

One calibration capture of the simulated head (:class:`cell.sim.camera.SimCamera`) renders the
plate in both 2448 × 2048 cameras of the standard head. This prints

1. where the time of one capture goes: the old point-sampling renderer
   (:mod:`measure.synth.target_reference`, ``supersample=1`` as the simulator used it, and
   ``supersample=2``, its default) and the new one (:mod:`measure.synth.targets`) stage by
   stage, and the transfer of the pair through :class:`cell.sim.camserver.CameraServer`;
2. per view time of each renderer over random plate views (each view seen whole by both
   cameras), the new one's first view (computing the head's rays) apart;
3. corner accuracy: the features OpenCV detects (:func:`measure.target.find_target`, with
   ``cornerSubPix`` as the calibration uses it) against the exact projection of the plate's
   features (``StereoCalibration.project``), RMS and max (px), for each renderer.

Run: ``PYTHONPATH=. python benchmarks/render_speed.py [--views 6] [--circles]``.
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from scipy.spatial.transform import Rotation

from cell.camera import NetworkCamera, StereoPair
from cell.sim.camserver import CameraServer
from measure.synth import targets as fast
from measure.synth.heads import standard_stereo
from measure.synth.pixel_rays import pixel_rays
from measure.synth.target_reference import render_target_pair_reference
from measure.target import TargetSpec, find_target

#: the built-in cell's board (cell/data/motorcycle_frame.yaml) and a circle grid
BOARD = TargetSpec("chessboard", 9, 6, 0.009)
CIRCLES = TargetSpec("circles", 4, 11, 0.004)


def views(stereo, spec: TargetSpec, n: int, seed: int = 1) -> list[np.ndarray]:
    """``n`` plate poses ``T_left_plate`` at 0.2–0.35 m, tilted up to 35°, all features inside
    both images with a 20 px margin."""
    rng = np.random.default_rng(seed)
    w, h = stereo.image_size
    pts = spec.object_points()
    centre = 0.5 * (pts.min(axis=0) + pts.max(axis=0))
    out: list[np.ndarray] = []
    while len(out) < n:
        T = np.eye(4)
        tilt = rng.uniform(0, np.radians(35))
        axis = rng.normal(size=3) * [1, 1, 0]
        R = Rotation.from_rotvec(tilt * axis / np.linalg.norm(axis)) * Rotation.from_euler(
            "z", rng.uniform(-0.5, 0.5)
        )
        T[:3, :3] = R.as_matrix()
        aim = np.array([rng.uniform(-0.02, 0.07), rng.uniform(-0.03, 0.03), 1.0])
        T[:3, 3] = aim * rng.uniform(0.2, 0.35) - T[:3, :3] @ centre
        X = pts @ T[:3, :3].T + T[:3, 3]
        ok = True
        for side in ("left", "right"):
            p = stereo.project(X, side)
            ok &= bool(np.all((p > 20) & (p < [w - 20, h - 20])))
        if ok:
            out.append(T)
    return out


def corner_errors(stereo, spec, T, pair) -> np.ndarray | None:
    """Detected minus true feature positions (2N, 2, px) of both images, None if missed."""
    X = spec.object_points() @ T[:3, :3].T + T[:3, 3]
    errs = []
    for side, img in (("left", pair.left), ("right", pair.right)):
        det = find_target(img, spec)
        if det.points is None:
            return None
        true = stereo.project(X, side)
        # a chessboard with an even side count may be found in reverse order (180° turn)
        e = min((det.points - true, det.points[::-1] - true), key=lambda e: np.abs(e).sum())
        errs.append(e)
    return np.concatenate(errs)


def stage_times(stereo, spec, T) -> list[tuple[str, float]]:
    """Seconds of the new renderer's stages for the left camera of one view (as
    :func:`measure.synth.targets._render_side` runs them: the plate over its box and margins,
    the region's blur, the frame's noise, one compiled pass adding it and quantising)."""
    rng = np.random.default_rng(0)
    R, t = T[:3, :3], T[:3, 3]
    w, h = stereo.image_size
    rows = []
    t0 = time.perf_counter()
    args = fast._plate_args(stereo, "left", R, t, spec, fast.VIGNETTING, 255.0, 0.7)
    base = fast._surround(stereo, "left", 0.7)
    (x0, y0, x1, y1), (ix0, iy0, ix1, iy1) = fast._region(args[2], 0.7, w, h)
    img = np.empty((y1 - y0, x1 - x0), dtype=np.float32)
    fast.plate_region(*args[:2], np.array([x0, y0, x1, y1]), *args[2:], img)
    rows.append((f"plate: {x1 - x0}x{y1 - y0} px region", time.perf_counter() - t0))
    t0 = time.perf_counter()
    img = fast.cv2.GaussianBlur(img, (0, 0), 0.7)
    rows.append(("optics blur of the region", time.perf_counter() - t0))
    t0 = time.perf_counter()
    fast.cv2.setRNGSeed(int(rng.integers(0, 2**31 - 1)))
    dn = np.empty((h, w), dtype=np.float32)
    fast.cv2.randn(dn, 0.0, 2.0)
    rows.append(("noise (cv2.randn, 5 MP)", time.perf_counter() - t0))
    t0 = time.perf_counter()
    out = np.empty((h, w), dtype=np.uint8)
    fast.quantize_u8(base, dn, 0, 0, out)
    inner = np.ascontiguousarray(img[iy0 - y0 : iy1 - y0, ix0 - x0 : ix1 - x0])
    fast.quantize_u8(inner, dn, ix0, iy0, out)
    rows.append(("noise added, 8 bits (one pass)", time.perf_counter() - t0))
    return rows


class _Fixed:
    """A camera that always returns one pair (to time the transport alone)."""

    def __init__(self, pair: StereoPair) -> None:
        self.pair = pair

    def capture(self) -> StereoPair:
        return self.pair


def transfer_time(pair: StereoPair, n: int = 5) -> float:
    """Seconds per pair through CameraServer → NetworkCamera on localhost."""
    with CameraServer(_Fixed(pair)).start() as server:
        cam = NetworkCamera(server.url, standard_stereo())
        cam.capture()
        t0 = time.perf_counter()
        for _ in range(n):
            got = cam.capture()
        dt = (time.perf_counter() - t0) / n
        cam.close()
    assert np.array_equal(got.left, pair.left)
    return dt


def run(spec: TargetSpec, n_views: int, n_ss2: int) -> None:
    stereo = standard_stereo()
    Ts = views(stereo, spec, n_views)
    print(f"\n== {spec.kind} {spec.cols}x{spec.rows}, pitch {spec.pitch_m * 1e3:g} mm; "
          f"{n_views} views, head {stereo.image_size[0]}x{stereo.image_size[1]} ==")  # fmt: skip
    t0 = time.perf_counter()
    for side in ("left", "right"):
        pixel_rays(stereo, side)
    t_rays = time.perf_counter() - t0
    t0 = time.perf_counter()
    first = fast.render_target_pair(stereo, spec, Ts[0], seed=0)
    t_first = time.perf_counter() - t0

    results = {}
    renderers = [
        ("old, supersample=1 (sim)", lambda T, i: render_target_pair_reference(
            stereo, spec, T, supersample=1, seed=i), n_views),
        ("old, supersample=2", lambda T, i: render_target_pair_reference(
            stereo, spec, T, supersample=2, seed=i), n_ss2),
        ("new (area integral)", lambda T, i: fast.render_target_pair(stereo, spec, T, seed=i),
         n_views),
    ]  # fmt: skip
    for name, fn, n in renderers:
        times, cpu, errs, missed = [], [], [], 0
        for i, T in enumerate(Ts[:n]):
            t0, c0 = time.perf_counter(), time.process_time()
            pair = fn(T, i)
            times.append(time.perf_counter() - t0)
            cpu.append(time.process_time() - c0)
            e = corner_errors(stereo, spec, T, pair)
            if e is None:
                missed += 1
            else:
                errs.append(e)
        E = np.concatenate(errs) if errs else np.zeros((0, 2))
        d = np.hypot(E[:, 0], E[:, 1])
        results[name] = (
            np.median(times),
            np.median(cpu),
            n,
            missed,
            np.sqrt(np.mean(d**2)),
            d.max(),
            E.mean(0),
        )

    print("\n1. where one capture's time goes (s)")
    print(f"   head rays, once per head (both; 0: cached)   {t_rays:8.3f}")
    print(f"   new renderer, first view (after the rays)     {t_first:8.3f}")
    for stage, dt in stage_times(stereo, spec, Ts[0]):
        print(f"   new, left camera: {stage:28s} {dt:8.3f}")
    print(f"   transfer of the pair through CameraServer     {transfer_time(first):8.3f}")
    print(
        "\n2./3. per view (both cameras; median wall and CPU s), corner accuracy vs exact "
        "projection"
    )
    print(f"   {'renderer':28s} {'views':>5s} {'s/view':>8s} {'cpu s':>7s} {'missed':>6s} "
          f"{'RMS px':>7s} {'max px':>7s} {'mean dx, dy px':>16s}")  # fmt: skip
    for name, (dt, dc, n, missed, rms, mx, mean) in results.items():
        print(f"   {name:28s} {n:5d} {dt:8.3f} {dc:7.3f} {missed:6d} {rms:7.4f} {mx:7.4f} "
              f"{mean[0]:+8.4f},{mean[1]:+.4f}")  # fmt: skip
    old, new = results["old, supersample=1 (sim)"], results["new (area integral)"]
    print(f"   speed-up over the simulator's old renderer: {old[0] / new[0]:.1f}x wall, "
          f"{old[1] / new[1]:.1f}x cpu (median s/view; the machine's load varies)")  # fmt: skip


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--views", type=int, default=6, help="views per renderer")
    ap.add_argument("--ss2-views", type=int, default=3, help="views for old supersample=2")
    ap.add_argument("--circles", action="store_true", help="also the circle grid")
    args = ap.parse_args()
    run(BOARD, args.views, args.ss2_views)
    if args.circles:
        run(CIRCLES, args.views, args.ss2_views)


if __name__ == "__main__":
    main()
