"""Public real hand-eye data sets against ``holecell calibrate hand-eye``, plain OpenCV and the
answer the data's authors published (issue 18, item 6; results in
``docs/calibration_real_data.md``).

The data are not in the repository; fetch them into a scratch folder and pass that folder
(nothing here downloads anything):

1. ``convert visp DIR -o OUT`` / ``convert kuka DIR -o OUT``: read a data set
   (``handeye_sets_io``), write ``OUT/poses.csv`` (``image,x_m,y_m,z_m,qx,qy,qz,qw``: the
   flange pose in the robot base), ``OUT/intrinsics.yaml`` (OpenCV FileStorage; shipped ones,
   or calibrated from the same images with OpenCV when the set has none) and print the
   ``holecell calibrate hand-eye`` command for it.
2. ``compare OUT [--holecell FILE ...]``: read ``OUT`` back (so the OpenCV column sees exactly
   what the CLI sees), run every OpenCV method (``handeye_opencv_baseline``) and print, per
   answer, the difference to the published one (mm, deg; to OpenCV's PARK where the authors
   publish no transform), the reprojection RMS on the views and
   ViSP's consistency residual. ``--holecell`` adds the CLI's answer (a YAML/JSON file holding
   ``T_tool0_camera: {xyz, quat_xyzw}``).

Usage::

    .venv/bin/python benchmarks/handeye_public_sets.py convert visp \
        /work/scratch/realdata/visp/apps/calibration/hand-eye/data-eye-in-hand -o /tmp/he_visp
    .venv/bin/python benchmarks/handeye_public_sets.py compare /tmp/he_visp
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np
import yaml
from scipy.spatial.transform import Rotation

sys.path.insert(0, str(Path(__file__).parent))

import handeye_opencv_baseline as cvb
from handeye_sets_io import (
    Board,
    DataSetError,
    pose_matrix,
    quat_xyzw,
    read_intrinsics,
    read_poses_csv,
    read_set,
    write_intrinsics,
    write_poses_csv,
)


def convert(kind: str, folder: str, out: Path) -> int:
    """Write ``poses.csv``, ``intrinsics.yaml`` and ``set.json`` into ``out``."""
    ds = read_set(kind, folder)
    out.mkdir(parents=True, exist_ok=True)
    write_poses_csv(out / "poses.csv", ds)
    rows = read_poses_csv(out / "poses.csv")
    views = cvb.collect_views(rows, ds.folder, ds.board)
    if ds.K is not None:
        K, dist, note = ds.K, ds.dist, f"intrinsics shipped with {ds.name}"
        print(f"{ds.name}: intrinsics from the data set (fx {K[0, 0]:.2f} px, no distortion)")
    else:
        K, dist, rms = cvb.calibrate_intrinsics(views)
        note = (
            f"calibrated with cv2.calibrateCamera from the {len(views.names)} views, {rms:.3f} px"
        )
        print(
            f"{ds.name}: intrinsics {note}: fx {K[0, 0]:.2f} fy {K[1, 1]:.2f} "
            f"cx {K[0, 2]:.2f} cy {K[1, 2]:.2f} dist {np.round(dist, 4).tolist()}"
        )
    write_intrinsics(out / "intrinsics.yaml", K, dist, views.size_wh, note)
    meta = {
        "name": ds.name,
        "images": str(ds.folder),
        "board": vars(ds.board),
        "views": len(ds.images),
        "detected": len(views.names),
        "dropped": views.dropped,
        "reversed_by_detector": views.flipped,
        "published_T_tool0_camera": None if ds.published is None else ds.published.tolist(),
        "published_T_base_board": (
            None if ds.published_base_board is None else ds.published_base_board.tolist()
        ),
    }
    (out / "set.json").write_text(json.dumps(meta, indent=1))
    b = ds.board
    print(f"  {len(ds.images)} views, board found in {len(views.names)}; dropped {views.dropped}")
    print(f"  detector order reversed (fixed here) in {len(views.flipped)}: {views.flipped}")
    if b.pattern in ("chessboard", "circles"):
        print(
            f"  holecell calibrate hand-eye --images {ds.folder} --poses {out / 'poses.csv'} "
            f"--intrinsics {out / 'intrinsics.yaml'} --pattern {b.pattern} --cols {b.cols} "
            f"--rows {b.rows} --pitch {b.pitch_m}"
        )
    else:
        print(f"  board is {b.pattern}: --pattern takes chessboard|circles only")
    return 0


def _find_key(doc, key: str):
    if isinstance(doc, dict):
        if key in doc:
            return doc[key]
        for v in doc.values():
            hit = _find_key(v, key)
            if hit is not None:
                return hit
    if isinstance(doc, list):
        for v in doc:
            hit = _find_key(v, key)
            if hit is not None:
                return hit
    return None


def read_holecell(path: str) -> np.ndarray:
    """``T_tool0_camera: {xyz, quat_xyzw}`` anywhere in a YAML/JSON file, as 4 × 4."""
    doc = yaml.safe_load(Path(path).read_text())
    pose = _find_key(doc, "T_tool0_camera")
    if not isinstance(pose, dict) or "xyz" not in pose or "quat_xyzw" not in pose:
        raise DataSetError(f"{path}: no T_tool0_camera {{xyz, quat_xyzw}}")
    return pose_matrix(Rotation.from_quat(pose["quat_xyzw"]).as_matrix(), pose["xyz"])


def compare(out: Path, holecell: list[str], jackknife: bool = False) -> int:
    """Print the comparison table for a converted set."""
    meta = json.loads((out / "set.json").read_text())
    board = Board(**meta["board"])
    K, dist = read_intrinsics(out / "intrinsics.yaml")
    views = cvb.collect_views(read_poses_csv(out / "poses.csv"), Path(meta["images"]), board)
    T_cb = cvb.camera_board_poses(views, K, dist)
    answers = cvb.opencv_answers(views, T_cb)
    pub = meta["published_T_tool0_camera"]
    if pub is not None:
        answers = {
            "published": {
                "X": np.array(pub),
                "base_board": np.array(meta["published_T_base_board"]),
            },
            **answers,
        }
    if cvb.is_valid(answers["PARK"]["X"]):
        X0 = answers["PARK"]["X"]
        X, Tb = cvb.joint_refinement(views, X0, cvb.board_in_base(views, X0, T_cb), K, dist)
        answers["reproj-LM"] = {"X": X, "base_board": Tb}
    for i, path in enumerate(holecell):
        answers[f"holecell{'' if i == 0 else i}"] = {"X": read_holecell(path), "base_board": None}
    # differences against the published answer; a set without one is compared with PARK's
    ref_name = "published" if pub is not None else "PARK"
    ref = answers[ref_name]["X"] if cvb.is_valid(answers[ref_name]["X"]) else None
    print(f"dt, dR against: {ref_name}")
    print(f"{meta['name']}: {len(views.names)} views used of {meta['views']}")
    print(
        f"{'answer':<12} {'x mm':>8} {'y mm':>8} {'z mm':>8} {'dt mm':>7} {'dR deg':>7} "
        f"{'RMS px':>7} {'cons deg':>8} {'cons mm':>7}"
    )
    rows = {}
    for name, a in answers.items():
        X = a["X"]
        if not cvb.is_valid(X):
            why = a.get("error") or f"not a pose: {np.round(X, 4).tolist()}"
            print(f"{name:<12} failed: {why}")
            rows[name] = {"failed": why}
            continue
        start = (
            a["base_board"] if a["base_board"] is not None else cvb.board_in_base(views, X, T_cb)
        )
        rms, _ = cvb.reprojection_rms(views, X, start, K, dist, refit=True)
        cons_deg, cons_mm = cvb.consistency(views, X, T_cb)
        dt, dR = cvb.difference(X, ref) if ref is not None else (float("nan"),) * 2
        t = X[:3, 3] * 1e3
        print(
            f"{name:<12} {t[0]:8.2f} {t[1]:8.2f} {t[2]:8.2f} {dt:7.2f} {dR:7.3f} {rms:7.3f} "
            f"{cons_deg:8.3f} {cons_mm:7.2f}"
        )
        rows[name] = {
            "t_mm": t.tolist(),
            "quat_xyzw": quat_xyzw(X[:3, :3]).tolist(),
            "dt_mm": dt,
            "dR_deg": dR,
            "rms_px": rms,
            "consistency_deg": cons_deg,
            "consistency_mm": cons_mm,
        }
    if a := answers.get("published"):
        rms, _ = cvb.reprojection_rms(views, a["X"], a["base_board"], K, dist, refit=False)
        print(f"published with its own T_base_board (no refit): {rms:.3f} px")
    if jackknife:
        for name, s in cvb.jackknife(views, T_cb, K, dist).items():
            print(
                f"leave-one-view-out sigma {name:<10} xyz {np.round(s[:3], 3).tolist()} mm, "
                f"rotation {np.round(s[3:], 4).tolist()} deg"
            )
            rows[name]["jackknife_sigma_mm_deg"] = s.tolist()
    (out / "compare.json").write_text(json.dumps(rows, indent=1))
    return 0


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    c = sub.add_parser("convert", help="data-set folder -> poses.csv, intrinsics.yaml")
    c.add_argument("kind", choices=("visp", "kuka"))
    c.add_argument("folder")
    c.add_argument("-o", "--out", required=True, type=Path)
    m = sub.add_parser("compare", help="OpenCV methods (and holecell's answer) on a converted set")
    m.add_argument("out", type=Path)
    m.add_argument("--holecell", nargs="*", default=[], help="holecell output file(s)")
    m.add_argument(
        "--jackknife", action="store_true", help="leave-one-view-out sigmas (PARK, reproj-LM)"
    )
    args = ap.parse_args(argv)
    try:
        if args.cmd == "convert":
            return convert(args.kind, args.folder, args.out)
        return compare(args.out, args.holecell, args.jackknife)
    except DataSetError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    raise SystemExit(main())
