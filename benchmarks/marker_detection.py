"""Reference markers: ring code vs adjacent AprilTag, on rendered and blurred survey views.

For each design (:data:`measure.markers.RING_DESIGN`, :data:`measure.markers.APRILTAG_DESIGN`) the
same random views are rendered (:func:`measure.synth.markers.render_markers_pair`, both cameras
of the standard head): dots of 5 and 10 mm at 0.2–1.0 m, tilted 0–60°, optics blur σ 0.5–2.0 px,
read noise 1–3 DN, 8 bits. Each marker seen by a camera is one observation. Printed:

1. per design: detection rate, false identifications (a code read on a true marker that is not
   its code) per 1000 observations, detections where there is no marker, the centre error
   against the true projected centre (ideal pixels; RMS and worst of the radial error) without
   and with the perspective-bias correction, the same for an independent centre (OpenCV's
   ``fitEllipse`` on the dot's thresholded contour, bias-corrected), the fit's stated σ against
   the error (RMS of error/σ per axis), and the detection time per 5 MP image;
2. detection rate by dot size and distance, by tilt, by blur;
3. the table of 1. on stress views beyond the detectors' limits (``STRESS``: blur σ 2-3.5 px,
   noise 3-6 DN, 5 mm dots at 0.6-1.2 m, tilts to 75°), where reads fail: refused or misread;
4. false detections on hole-only scenes (:func:`measure.synth.render_hole_pair`, standard and
   realistic options);
5. the time to draw a stop's markers into one image.

Run: ``PYTHONPATH=. python benchmarks/marker_detection.py [--views 40] [--stress 20] [--holes 10]``.
"""

from __future__ import annotations

import argparse
import time
from dataclasses import dataclass

import cv2
import numpy as np

from measure.markers import (
    APRILTAG_DESIGN,
    RING_DESIGN,
    circle_center_bias_px,
    detect_markers,
)
from measure.synth import RenderOptions, hole_in_view, render_hole_pair, standard_stereo
from measure.synth.marker_scenes import marker_grid_view
from measure.synth.markers import render_markers_pair

DESIGNS = (RING_DESIGN, APRILTAG_DESIGN)


@dataclass
class Obs:
    """One marker seen by one camera."""

    design: str
    dot_mm: int
    z_m: float
    tilt_deg: float
    blur: float
    found: bool = False
    wrong_code: bool = False
    err_raw: float = np.nan
    err_corr: float = np.nan
    err_cv: float = np.nan
    pull: tuple[float, float] = (np.nan, np.nan)


def _camera(st, side):
    return (st.K_left, st.dist_left) if side == "left" else (st.K_right, st.dist_right)


def _truth(st, m, side):
    C, N = np.asarray(m.center_m, float), np.asarray(m.normal, float)
    if side == "right":
        C, N = st.R @ C + st.T, st.R @ N
    K = _camera(st, side)[0]
    p = K @ C
    return p[:2] / p[2], C, N


def _ideal(pt, K, d):
    return cv2.undistortPoints(np.asarray(pt, float).reshape(1, 1, 2), K, d, P=K).ravel()


def opencv_centre(img: np.ndarray, center: np.ndarray, axes: tuple) -> np.ndarray | None:
    """Independent centre: OpenCV's ``fitEllipse`` on the dot's contour, thresholded halfway
    between the crop's dark and bright levels (1st and 99th percentiles) in a crop around it
    (distorted image pixels); the contour holding the detected centre with about the detected
    ellipse's area."""
    major, minor = axes
    r = int(0.7 * major) + 3
    x, y = round(center[0]), round(center[1])
    x0, y0 = max(x - r, 0), max(y - r, 0)
    crop = img[y0 : y + r + 1, x0 : x + r + 1]
    if crop.size == 0:
        return None
    lo, hi = np.percentile(crop, [1, 99])
    _, bw = cv2.threshold(crop, 0.5 * (lo + hi), 255, cv2.THRESH_BINARY)
    cnts, _ = cv2.findContours(bw.astype(np.uint8), cv2.RETR_LIST, cv2.CHAIN_APPROX_NONE)
    area = np.pi * major * minor / 4
    c_crop = (float(center[0] - x0), float(center[1] - y0))
    for c in cnts:
        if len(c) < 12 or cv2.pointPolygonTest(c, c_crop, False) <= 0:
            continue
        if abs(cv2.contourArea(c) - area) > 0.3 * area:
            continue
        (cx, cy), _, _ = cv2.fitEllipse(c)
        return np.array([cx + x0, cy + y0])
    return None


@dataclass(frozen=True)
class Conditions:
    """Ranges the views are drawn from (uniform)."""

    z_m: tuple[float, float] = (0.2, 1.0)
    blur_px: tuple[float, float] = (0.5, 2.0)
    noise_dn: tuple[float, float] = (1.0, 3.0)
    max_tilt_deg: float = 60.0
    dots_m: tuple[float, ...] = (0.005, 0.010)


NOMINAL = Conditions()
#: beyond the detectors' limits: heavy blur and noise, small far dots, grazing views
STRESS = Conditions((0.6, 1.2), (2.0, 3.5), (3.0, 6.0), 75.0, (0.005,))


def run_views(
    n_views: int, seed: int, cond: Conditions = NOMINAL
) -> tuple[list[Obs], dict[str, list[float]], dict[str, int]]:
    st = standard_stereo()
    obs: list[Obs] = []
    times: dict[str, list[float]] = {k: [] for d in DESIGNS for k in (d.kind, d.kind + " cpu")}
    ghosts = {d.kind: 0 for d in DESIGNS}
    for v in range(n_views):
        rng = np.random.default_rng([seed, v])
        dot_m = cond.dots_m[v % len(cond.dots_m)]
        z = float(rng.uniform(*cond.z_m))
        blur = float(rng.uniform(*cond.blur_px))
        opts = RenderOptions(blur_sigma_px=blur, read_noise_dn=float(rng.uniform(*cond.noise_dn)))
        for design in DESIGNS:
            ms = marker_grid_view(
                st, np.random.default_rng([seed, v, 7]), design, dot_m, z, cond.max_tilt_deg
            )
            r = render_markers_pair(st, ms, opts, seed=v)
            for side, img in (("left", r.left), ("right", r.right)):
                K, d = _camera(st, side)
                t0, c0 = time.perf_counter(), time.thread_time()
                dets = detect_markers(img, K, d, design=design)
                times[design.kind].append(time.perf_counter() - t0)
                times[design.kind + " cpu"].append(time.thread_time() - c0)
                truths = [_truth(st, m, side) for m in ms]
                used = set()
                for m, (proj, C, N) in zip(ms, truths, strict=True):
                    tilt = float(np.degrees(np.arccos(min(1.0, abs(N @ C) / np.linalg.norm(C)))))
                    o = Obs(design.kind, round(dot_m * 1000), z, tilt, blur)
                    obs.append(o)
                    if not (0 <= proj[0] < st.image_size[0] and 0 <= proj[1] < st.image_size[1]):
                        obs.pop()
                        continue
                    for j, det in enumerate(dets):
                        ideal = _ideal(det.center_px, K, d)
                        if np.linalg.norm(ideal - proj) > 0.25 * det.ellipse[1][1]:
                            continue
                        used.add(j)
                        o.found = True
                        o.wrong_code = det.code != m.code
                        bias = circle_center_bias_px(K, C, N, 0.5 * dot_m)
                        o.err_raw = float(np.linalg.norm(ideal - proj))
                        e = ideal - bias - proj
                        o.err_corr = float(np.linalg.norm(e))
                        o.pull = (e[0] / det.sigma_px, e[1] / det.sigma_px)
                        q = opencv_centre(img, det.center_px, det.ellipse[1])
                        if q is not None:
                            o.err_cv = float(np.linalg.norm(_ideal(q, K, d) - bias - proj))
                ghosts[design.kind] += len(dets) - len(used)
    return obs, times, ghosts


def _rms(a):
    a = np.asarray([x for x in a if np.isfinite(x)])
    return (float(np.sqrt(np.mean(a**2))), float(a.max())) if len(a) else (np.nan, np.nan)


def print_summary(obs, times, ghosts, title: str) -> None:
    print(f"\n## {title} (both cameras; centre errors in ideal px, radial)\n")
    print(
        "| design | obs | detected | false id /1000 | no-marker detections | centre raw RMS / worst"
        " | corrected RMS / worst | OpenCV contour corrected RMS / worst | RMS err/σ"
        " | ms / image (wall, CPU) |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|")
    for d in DESIGNS:
        o = [x for x in obs if x.design == d.kind]
        f = [x for x in o if x.found]
        wrong = sum(x.wrong_code for x in f)
        raw, corr, cv = (
            _rms([getattr(x, k) for x in f]) for k in ("err_raw", "err_corr", "err_cv")
        )
        pulls = np.array([p for x in f if not x.wrong_code for p in x.pull])
        t = np.median(times[d.kind]) * 1000
        t_cpu = np.median(times[d.kind + " cpu"]) * 1000
        print(
            f"| {d.kind} | {len(o)} | {len(f) / max(len(o), 1):.1%}"
            f" | {1000 * wrong / max(len(o), 1):.1f}"
            f" | {ghosts[d.kind]} | {raw[0]:.3f} / {raw[1]:.3f} | {corr[0]:.3f} / {corr[1]:.3f}"
            f" | {cv[0]:.3f} / {cv[1]:.3f} | {np.sqrt(np.mean(pulls**2)):.2f}"
            f" | {t:.0f}, {t_cpu:.0f} |"
        )


def print_rates(obs) -> None:
    def table(title, key, bins):
        print(f"\n## Detection rate (and corrected centre RMS, px) by {title}\n")
        print("| " + title + " | " + " | ".join(d.kind for d in DESIGNS) + " |")
        print("|---|" + "---|" * len(DESIGNS))
        for name, test in bins:
            cells = []
            for d in DESIGNS:
                o = [x for x in obs if x.design == d.kind and test(key(x))]
                f = [x for x in o if x.found and not x.wrong_code]
                rms = _rms([x.err_corr for x in f])[0]
                cells.append(f"{len(f) / max(len(o), 1):.0%} of {len(o)} ({rms:.3f})" if o else "-")
            print(f"| {name} | " + " | ".join(cells) + " |")

    dist_bins = [
        (
            f"{mm} mm, {lo:.1f}-{hi:.1f} m",
            lambda k, mm=mm, lo=lo, hi=hi: k[0] == mm and lo <= k[1] < hi,
        )
        for mm in (5, 10)
        for lo, hi in ((0.2, 0.4), (0.4, 0.7), (0.7, 1.01))
    ]
    table("dot and distance", lambda x: (x.dot_mm, x.z_m), dist_bins)
    tilt_bins = [
        (f"{lo}-{hi}°", lambda k, lo=lo, hi=hi: lo <= k < hi)
        for lo, hi in ((0, 20), (20, 40), (40, 50), (50, 60), (60, 75))
    ]
    table("tilt", lambda x: x.tilt_deg, tilt_bins)
    blur_bins = [
        (f"σ {lo}-{hi} px", lambda k, lo=lo, hi=hi: lo <= k < hi)
        for lo, hi in ((0.5, 1.0), (1.0, 1.5), (1.5, 2.01))
    ]
    table("blur", lambda x: x.blur, blur_bins)


def hole_scenes(n: int) -> None:
    """False detections on hole-only scenes, both designs' detectors."""
    st = standard_stereo()
    counts = {d.kind: 0 for d in DESIGNS}
    variants = [
        RenderOptions(),
        RenderOptions(chamfer_m=4e-4, highlight=0.9),
        RenderOptions(object_fraction=0.5, wall_light=0.6, light_gradient=0.2),
        RenderOptions(lip_rounded=True, chamfer_m=5e-4, occlusion_fraction=0.3, blur_sigma_px=1.5),
    ]
    images = 0
    for k in range(n):
        rng = np.random.default_rng([99, k])
        c, nrm = hole_in_view(st, np.radians(rng.uniform(0, 45)), rng.uniform(0, 2 * np.pi))
        r = render_hole_pair(st, c, nrm, float(rng.uniform(0.004, 0.016)), variants[k % 4], seed=k)
        for img in (r.left, r.right):
            images += 1
            for d in DESIGNS:
                counts[d.kind] += len(detect_markers(img, design=d))
    print(f"\n## Hole-only scenes: markers reported in {images} images ({n} pairs, 4 variants)\n")
    print("| design | markers reported |\n|---|---|")
    for d in DESIGNS:
        print(f"| {d.kind} | {counts[d.kind]} |")


def render_times(repeats: int = 5) -> None:
    """Time to draw a stop's markers into one image: 4 and 12 markers (5 mm dots, 0.25 m)."""
    from measure.synth.marker_draw import draw_markers

    st = standard_stereo()
    print("\n## Drawing markers into one image (5 mm dots at 0.25 m, 20° tilt)\n")
    print("| design | markers | ms per image, wall and CPU (best of 5) |\n|---|---|---|")
    for d in DESIGNS:
        for n in (4, 12):
            ms = marker_grid_view(st, np.random.default_rng(n), d, 0.005, 0.25, 20.0, n)
            ms = (ms * n)[:n]  # the view holds fewer: repeat them (the cost is the same)
            img = np.zeros((st.image_size[1], st.image_size[0]), np.float32)
            draw_markers(img, st, "left", ms, 0.7, 0.25)
            best = best_cpu = float("inf")
            for _ in range(repeats):
                t0, c0 = time.perf_counter(), time.thread_time()
                draw_markers(img, st, "left", ms, 0.7, 0.25)
                best = min(best, time.perf_counter() - t0)
                best_cpu = min(best_cpu, time.thread_time() - c0)
            print(f"| {d.kind} | {n} | {best * 1000:.0f}, {best_cpu * 1000:.0f} |")


def print_designs() -> None:
    print("\n## Designs\n")
    print("| design | codes | printed radius (dot diameters) | 5 mm dot: radius (mm) |")
    print("|---|---|---|---|")
    for d in DESIGNS:
        r = d.outer_radius(1.0)
        print(f"| {d.kind} | {d.n_codes()} | {r:.2f} | {d.outer_radius(0.005) * 1000:.1f} |")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--views", type=int, default=40)
    ap.add_argument("--holes", type=int, default=10)
    ap.add_argument("--stress", type=int, default=20, help="views under STRESS conditions")
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args()
    t0 = time.time()
    print_designs()
    obs, times, ghosts = run_views(args.views, args.seed)
    print_summary(obs, times, ghosts, "Per design, nominal views")
    print_rates(obs)
    if args.stress:
        st_obs, st_times, st_ghosts = run_views(args.stress, args.seed + 1000, STRESS)
        print_summary(st_obs, st_times, st_ghosts, f"Stress views {STRESS}")
    hole_scenes(args.holes)
    render_times()
    print(f"\n({args.views} views per design, {time.time() - t0:.0f} s wall)")


if __name__ == "__main__":
    main()
