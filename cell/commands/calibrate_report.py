"""Terminal report of a cell calibration (``holecell calibrate hand-eye``, ``calibrate cell``)."""

from __future__ import annotations

import numpy as np

from cell.calibration.estimate import CalibrationResult, PoseEstimate, pose_error


def _pose_line(name: str, p: PoseEstimate) -> str:
    from scipy.spatial.transform import Rotation

    xyz = p.T[:3, 3] * 1e3
    s = p.sigma_xyz_m * 1e3
    rpy = np.rad2deg(Rotation.from_matrix(p.T[:3, :3]).as_euler("xyz"))
    sr = np.rad2deg(p.sigma_rot_rad)
    pos = ", ".join(f"{v:.3f} ± {e:.3f}" for v, e in zip(xyz, s, strict=True))
    rot = ", ".join(f"{v:.4f}" for v in rpy)
    srot = ", ".join(f"{e:.4f}" for e in sr)
    return f"{name}: xyz [{pos}] mm, rpy [{rot}] deg (rotation sigma [{srot}] deg)"


def dh_term_text(name: str, value: float, sigma: float) -> str:
    """A D-H error in display units: ``a1 +0.8900 ± 0.0100 mm`` for ``a1_m`` (m), ``theta2
    -0.0123 ± 0.0010 deg`` for ``theta2_rad`` (rad); the unit follows the value it labels."""
    stem, unit = name.rsplit("_", 1)
    scale, shown = (1e3, "mm") if unit == "m" else (float(np.rad2deg(1.0)), "deg")
    return f"{stem} {value * scale:+.4f} ± {sigma * scale:.4f} {shown}"


def print_result(result: CalibrationResult) -> None:
    """Print the estimates with their sigmas, the fixed terms, residuals and OpenCV's answers."""
    cal = result.calibration
    c = cal.counts
    print(
        f"{c['views']} views, {c['points']} corners, {c['parameters']} unknowns, "
        f"corner noise s = {cal.sigma_px:.3f} px (from the residuals)"
    )
    fs = cal.flange_scatter
    if fs and not str(fs.get("source", "")).startswith("not modelled"):
        print(
            f"flange pose scatter per view {float(fs['sigma_m']) * 1e3:.3f} mm, "
            f"{np.rad2deg(float(fs['sigma_rad'])):.4f} deg per axis ({fs['source']}): "
            "in the covariance"
        )
    elif fs:
        print(f"flange pose scatter {fs['source']}: the covariance holds corner noise only")
    width = max(len(v.name) for v in cal.views)
    for v in cal.views:
        right = "" if np.isnan(v.rms_right_px) else f"  right {v.rms_right_px:.3f} px"
        print(f"  {v.name:<{width}}  left {v.rms_left_px:.3f} px{right}")
    rms = ", ".join(f"{k} {v:.3f} px" for k, v in cal.residual_rms_px.items())
    print(f"reprojection RMS: {rms}")
    print(_pose_line("T_tool0_camera", cal.T_tool0_camera))
    print(_pose_line("T_base_target", cal.T_base_target))
    if cal.T_left_right is not None:
        print(_pose_line("T_left_right", cal.T_left_right))
    free = [t for t in cal.dh_terms if t.free]
    if free:
        print(f"D-H errors: {', '.join(dh_term_text(t.name, t.value, t.sigma) for t in free)}")
    if result.intrinsics:
        shown = ", ".join(f"{n.removeprefix('intrinsics.')} {v:+.3g}±{e:.2g}"
                          for n, (v, e) in result.intrinsics.items())  # fmt: skip
        print(
            f"lens corrections (fx..cy px; k, p: OpenCV distortion; stereo.json unchanged): {shown}"
        )
    for name, reason in result.report.fixed.items():
        print(f"  fixed {name}: {reason}")
    print(
        f"condition number {result.report.condition_free:.3g} (column-normalised), "
        f"solve {result.timings['total_s']:.2f} s"
    )
    if result.initial is not None:
        for cand in result.initial.candidates:
            if not np.isfinite(cand.spread_m):
                print(f"  OpenCV {cand.method}: failed")
                continue
            dp, da = pose_error(cand.T_tool0_camera, cal.T_tool0_camera.T)
            print(
                f"  OpenCV {cand.method}: hand-eye differs by {dp * 1e3:.3f} mm, "
                f"{np.rad2deg(da):.4f} deg (target spread {cand.spread_m * 1e3:.3f} mm)"
            )
    for note in cal.notes:
        if note.startswith("warning"):
            print(note)
