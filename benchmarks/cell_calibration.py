"""The cell calibration in the simulated cell, against the simulator's exact truth.

For each seed: the built-in cell with the drawn truth ``CellTruth.drawn(seed)`` (D-H errors,
the head's mount, the base, the target's placement, the arm's repeatability, the head off its
stereo calibration by a draw of its stated uncertainty), the calibration tour (planned once as
``holecell calibrate cell`` plans it, ``--views`` views, or ``--tour``) run on the simulated
controller and head (``cell.calibration.capture.capture``), then the adjustment, once per
``--variant``: ``fixed`` takes the intrinsics from stereo.json as exact, ``intrinsics``
estimates each camera's fx, fy, cx, cy with the rest (marginalised).

Per seed and variant, before (the nominal cell) and after:

- hand-eye error (mm, deg) against the truth in the calibration's gauge
  (``cell.demo.calibration_truth``; targets <= 0.05 mm and <= 0.01 deg);
- TCP position error (RMS and worst, um) at 200 random joint poses looking into the part's
  volume (random points in the holes' bounding box, each viewed along a hole's normal at the
  standoff with a random roll, IK nearest that hole's tour configuration), the model's chain
  against the true one in ``base_link`` (target <= 30 um RMS after);
- the TCP's stated sigma there (RMS of ``sqrt(trace)`` of the calibration's covariance
  propagated by ``CalibratedKinematics.point_covariance``);
- the share of the free parameters within 2 stated sigmas of the truth (target 90-99 %);
- robot time (the tour's planned time; target <= 180 s) and solve time (target <= 10 s;
  wall and CPU time of this process: the machine may be shared);
- the reference: plain OpenCV (``calibrateHandEye`` PARK; ``calibrateRobotWorldHandEye``
  SHAH) on the same views with the nominal kinematics.

``--cache DIR`` keeps each seed's captures (and the tour), so a second run only solves.

    python benchmarks/cell_calibration.py --seeds 10 --views 120 --cache /tmp/calcache
"""

from __future__ import annotations

import argparse
import pickle
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from cell.calibration.capture import (
    PLANE_TOLERANCE_PX,
    CaptureSettings,
    TourCapture,
    check_calibration_tour,
    observations_of,
    plane_outliers,
)
from cell.calibration.estimate import (
    Cameras,
    SolveOptions,
    parameter_errors,
    pose_error,
    solve_calibration,
)
from cell.calibration.plan import calibrate_plan_options, plan_cell_calibration
from cell.calibration.use import CalibratedKinematics
from cell.camera import cell_stereo
from cell.config import load_builtin_cell
from cell.config.tours import hole_stops
from cell.demo.calibration_truth import tcp_errors_m, true_state
from cell.link.client import ControllerClient
from cell.sim.session import SimCell
from cell.sim.truth import CellTruth
from cell.sim.world import WorldOptions
from planner.calibration import load_caltour
from robots.transforms import invert

VARIANTS = {
    "fixed": SolveOptions(),
    "intrinsics": SolveOptions(estimate_intrinsics=True),
}


def test_poses(cell, n: int, seed: int = 12345) -> np.ndarray:
    """``n`` joint vectors (rad) looking into the part's volume (module docstring)."""
    arm, rng = cell.build_arm(), np.random.default_rng(seed)
    holes = cell.holes_in_cell()
    ids, stops = hole_stops(cell)
    by_id = {h.id: h for h in holes}
    P = np.array([h.position_m for h in holes])
    lo, hi = P.min(axis=0), P.max(axis=0)
    out: list[np.ndarray] = []
    while len(out) < n:
        k = int(rng.integers(len(ids)))
        normal = np.asarray(by_id[ids[k]].normal, float)
        p = rng.uniform(lo, hi)
        z = -normal / np.linalg.norm(normal)
        x = np.cross(z, [1.0, 0.0, 0.0] if abs(z[0]) < 0.9 else [0.0, 1.0, 0.0])
        x /= np.linalg.norm(x)
        a = rng.uniform(0, 2 * np.pi)
        x = np.cos(a) * x + np.sin(a) * np.cross(z, x)
        T = np.eye(4)
        T[:3, :3] = np.column_stack([x, np.cross(z, x), z])
        T[:3, 3] = p - cell.tool.standoff_m * z
        ik = arm.ik(T)
        if ik.ok:
            sol = np.asarray(ik.solutions, float)
            out.append(sol[np.argmin(np.abs(sol - stops[k]).sum(axis=1))])
    return np.array(out)


def capture_seed(cell, tour, seed: int, speed: float, cache: Path | None) -> dict:
    """Run the tour on the simulated cell of ``seed``; the captures and the truth."""
    path = None if cache is None else cache / f"seed{seed}_{len(tour.tour.stops)}.pkl"
    if path is not None and path.exists():
        return pickle.loads(path.read_bytes())
    spec = check_calibration_tour(cell, tour, "benchmark tour")
    with SimCell.start(cell, WorldOptions(speed=speed, truth=CellTruth.drawn(seed, cell))) as sim:
        client = ControllerClient(sim.url)
        client.connect()
        try:
            cap = TourCapture(tour.tour, client, sim.camera, spec, CaptureSettings(0.0)).run()
        finally:
            client.close()
        ts = sim.camera.true_stereo
        T_rl = np.eye(4)
        T_rl[:3, :3], T_rl[:3, 3] = ts.R, ts.T
        t_mid = 0.5 * (cap.start_time_s + cap.end_time_s)
        truth = true_state(cell.build_robot().dh, sim.camera.geometry, invert(T_rl), t_mid)
        data = {"captures": cap, "truth": truth, "T_tcp_left": sim.camera.geometry.T_tcp_left}
    if path is not None:
        path.write_bytes(pickle.dumps(data))
    return data


def off_plane_views(cell, captures) -> list[str]:
    """Views with a corner off the plate's plane (``cell.calibration.capture.orient``): captures
    cached before the capture repaired or refused them."""
    st, spec = cell_stereo(cell), cell.calibration_target.target_spec()
    out = []
    for v in captures.views:
        for pts, K, d in ((v.corners_left_px, st.K_left, st.dist_left),
                          (v.corners_right_px, st.K_right, st.dist_right)):  # fmt: skip
            if pts is not None and plane_outliers(pts, spec, K, d)[0].max() > PLANE_TOLERANCE_PX:
                out.append(v.id)
                break
    return out


def figures(cell, data: dict, options: SolveOptions, Q: np.ndarray) -> dict:
    """One seed, one variant: the figures of the module docstring."""
    dh = cell.build_robot().dh
    truth, T_tcp_left = data["truth"], data["T_tcp_left"]
    captures = data["captures"]
    dropped = off_plane_views(cell, captures)
    if dropped:
        captures = replace(captures, views=tuple(v for v in captures.views if v.id not in dropped))
    obs = observations_of(captures, cell.calibration_target.target_spec(),
                          Cameras.from_stereo(cell_stereo(cell)), "benchmark")  # fmt: skip
    cpu = time.process_time()
    res = solve_calibration(obs, dh, options)
    cpu = time.process_time() - cpu
    cal = res.calibration
    T_left_tcp = invert(T_tcp_left)
    X0 = np.asarray(cell.T_tool0_tcp()) @ T_tcp_left

    def tcp(X, delta):
        e = tcp_errors_m(dh, truth, X, delta, T_left_tcp, Q)
        return float(np.sqrt(np.mean(e**2))), float(e.max())

    ck = CalibratedKinematics(cal)
    var = [np.trace(ck.point_covariance(q, T_left_tcp[:3, 3], "base")) for q in Q]
    errs = parameter_errors(cal, truth)
    z = np.array([errs[n] / cal.sigma(n) for n in cal.parameter_names])
    out = {
        "he0": pose_error(X0, truth.T_tool0_camera),
        "he": pose_error(cal.T_tool0_camera.T, truth.T_tool0_camera),
        "tcp0": tcp(X0, np.zeros(24)),
        "tcp": tcp(cal.T_tool0_camera.T, cal.delta),
        "tcp_sigma": float(np.sqrt(np.mean(var))),
        "within2": float(np.mean(np.abs(z) < 2.0)),
        "n_par": len(z),
        "solve_s": res.timings["total_s"],
        "solve_cpu_s": cpu,
        "fixed": len(res.report.fixed),
        "dropped": dropped,
    }
    for name in ("park", "shah"):
        cand = [c for c in res.initial.candidates if c.method == name and np.isfinite(c.spread_m)]
        if cand:
            out[name] = (*pose_error(cand[0].T_tool0_camera, truth.T_tool0_camera),
                         tcp(cand[0].T_tool0_camera, np.zeros(24))[0])  # fmt: skip
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=10)
    ap.add_argument("--first-seed", type=int, default=0)
    ap.add_argument("--views", type=int, default=120)
    ap.add_argument("--tour", type=Path, default=None, help="caltour.json (default: planned)")
    ap.add_argument(
        "--speed", type=float, default=1.0,
        help="simulation speed (1: the detection overlaps the moves as in the cell)",
    )  # fmt: skip
    ap.add_argument("--cache", type=Path, default=None, help="folder for captures and tour")
    ap.add_argument("--variant", choices=[*VARIANTS, "both"], default="both")
    args = ap.parse_args()
    cell = load_builtin_cell()
    if args.cache is not None:
        args.cache.mkdir(parents=True, exist_ok=True)
    tour_path = args.tour or (None if args.cache is None else args.cache / f"tour{args.views}.json")
    if tour_path is not None and tour_path.exists():
        tour = load_caltour(tour_path)
    else:
        t = time.perf_counter()
        tour = plan_cell_calibration(cell, cell_stereo(cell), calibrate_plan_options(args.views))
        print(f"planned {args.views} views in {time.perf_counter() - t:.0f} s")
        if tour_path is not None:
            tour.save(tour_path)
    p = tour.prediction
    print(f"tour: {len(tour.tour.stops)} views, robot time {tour.tour.cycle_time_s:.1f} s; "
          f"predicted TCP sigma {p.get('tcp_sigma_m', float('nan')) * 1e6:.1f} um")  # fmt: skip
    Q = test_poses(cell, 200)
    variants = list(VARIANTS) if args.variant == "both" else [args.variant]
    rows: dict[str, list[dict]] = {v: [] for v in variants}
    head = ("seed  variant     hand-eye before -> after (mm, deg)         TCP RMS (max) before -> "
            "after (um)   2sigma  solve   OpenCV park (mm, deg, TCP um)  shah")  # fmt: skip
    print(head)
    for seed in range(args.first_seed, args.first_seed + args.seeds):
        t = time.perf_counter()
        try:
            data = capture_seed(cell, tour, seed, args.speed, args.cache)
        except Exception as exc:  # a refused data set is a result of the benchmark
            print(f"{seed:4d}  refused: {exc}")
            continue
        wall = time.perf_counter() - t
        for v in variants:
            try:
                f = figures(cell, data, replace(VARIANTS[v]), Q)
            except Exception as exc:
                print(f"{seed:4d}  {v:<10}  refused: {exc}")
                continue
            rows[v].append(f)
            print(_row(f"{seed:4d}", v, f), flush=True)
        print(f"      (capture {wall:.0f} s wall, controller time "
              f"{data['captures'].robot_time_s:.1f} s)")  # fmt: skip
    for v in variants:
        if rows[v]:
            print(_summary(v, rows[v]))


def _row(tag: str, v: str, f: dict) -> str:
    def he(x):
        return f"{x[0] * 1e3:.3f}, {np.degrees(x[1]):.4f}"

    cv = "  ".join(f"{f[m][0] * 1e3:.3f}, {np.degrees(f[m][1]):.4f}, {f[m][2] * 1e6:.0f}"
                   for m in ("park", "shah") if m in f)  # fmt: skip
    return (f"{tag}  {v:<10}  {he(f['he0'])} -> {he(f['he'])}   {f['tcp0'][0] * 1e6:.0f} "
            f"({f['tcp0'][1] * 1e6:.0f}) -> {f['tcp'][0] * 1e6:.1f} ({f['tcp'][1] * 1e6:.0f}; "
            f"stated sigma {f['tcp_sigma'] * 1e6:.1f})   "
            f"{100 * f['within2']:.0f} % of {f['n_par']}  {f['solve_s']:.1f} s "
            f"({f['solve_cpu_s']:.1f} s CPU)   {cv}"
            + (f"  [dropped {', '.join(f['dropped'])}: a corner off the plate's plane]"
               if f["dropped"] else ""))  # fmt: skip


def _summary(v: str, rows: list[dict]) -> str:
    def agg(get, worst=max):
        x = np.array([get(r) for r in rows])
        return float(x.mean()), float(worst(x))

    he_m, he_r = agg(lambda r: r["he"][0]), agg(lambda r: r["he"][1])
    tcp, w2, sv = agg(lambda r: r["tcp"][0]), agg(lambda r: r["within2"], min), agg(
        lambda r: r["solve_s"])  # fmt: skip
    return (f"mean (worst) {v}: {len(rows)} seeds, hand-eye {he_m[0] * 1e3:.3f} "
            f"({he_m[1] * 1e3:.3f}) mm, {np.degrees(he_r[0]):.4f} ({np.degrees(he_r[1]):.4f}) "
            f"deg; TCP {tcp[0] * 1e6:.1f} ({tcp[1] * 1e6:.1f}) um RMS; within 2 sigma "
            f"{100 * w2[0]:.0f} ({100 * w2[1]:.0f}) %; "
            f"solve {sv[0]:.1f} ({sv[1]:.1f}) s")  # fmt: skip


if __name__ == "__main__":
    main()
