"""Plan the built-in motorcycle frame with another arm, given only its URDF (and its meshes).

The script writes a copy of the built-in cell whose ``robot.model`` is the URDF you give
(``robot.package_paths`` for its ``package://`` meshes), picks a home configuration for that
arm (the IK solution of the built-in home's TCP pose nearest to zero that is free of
collision with the cell's clearances), plans the tour with ``holecell plan``'s planner and
checks every trajectory sample against the arm's own collision meshes (clearances kept).
Nothing of the arm is committed to this repository; fetch a ROS-Industrial description and
expand its xacro first, e.g.::

    git clone https://github.com/ros-industrial/kuka_experimental
    pip install xacro       # in a scratch venv; $(find pkg) needs ROS or a package path
    xacro kuka_experimental/kuka_kr16_support/urdf/kr16_2.xacro > kr16_2.urdf
    .venv/bin/python examples/plan_with_urdf.py kr16_2.urdf \\
        --package-path kuka_experimental --out /tmp/kr16_cell

Prints the derived OPW parameters, the tour summary and the collision check; exits 0 when
every hole is in the tour and every sample is free, 1 otherwise.
"""

from __future__ import annotations

import argparse
import gc
import sys
import time
from pathlib import Path

import numpy as np
import yaml

from cell.config import builtin_cell_path, load_builtin_cell, load_cell
from planner import Options, TourPlanner
from robots import Arm


def _home_for(arm: Arm, T_cell_tcp: np.ndarray) -> np.ndarray | None:
    """The collision-free IK solution of ``T_cell_tcp`` nearest to q = 0 (rad), if any."""
    sols = arm.ik(T_cell_tcp).solutions
    free = [q for q in sols if not arm.in_collision(q)]
    return min(free, key=lambda q: float(np.abs(q).sum())) if free else None


def write_cell(urdf: Path, package_paths: list[Path], out: Path, base_xyz: list[float]) -> Path:
    """A copy of the built-in cell for the arm of ``urdf``; returns the cell file's path."""
    doc = yaml.safe_load(builtin_cell_path().read_text())
    builtin = load_builtin_cell()
    T_home_tcp = builtin.build_arm().fk(builtin.home_q())
    doc["name"] = f"motorcycle-frame-{urdf.stem}"
    doc["robot"]["model"] = str(urdf.resolve())
    doc["robot"]["package_paths"] = [str(p.resolve()) for p in package_paths]
    doc["robot"]["base"]["xyz"] = base_xyz
    out.mkdir(parents=True, exist_ok=True)
    path = out / "cell.yaml"
    path.write_text(yaml.safe_dump(doc, sort_keys=False))
    # the built-in home is an IRB 2600 configuration: find this arm's own for the same TCP pose
    T_cell_base = builtin.T_cell_base()
    T_cell_base[:3, 3] = base_xyz
    probe = Arm(urdf, T_cell_base=T_cell_base, package_paths=package_paths)
    probe.set_tool(builtin.T_tool0_tcp(), builtin.tool_shapes())
    probe.add_obstacles(builtin.obstacle_shapes())
    probe.set_clearance(builtin.robot.clearance_m, builtin.tool.clearance_m)  # as the cell's
    home = _home_for(probe, T_home_tcp)
    if home is None:
        raise SystemExit(f"{urdf}: no collision-free IK solution for the built-in home pose")
    doc["robot"]["home"] = [round(float(v), 6) for v in home]
    path.write_text(yaml.safe_dump(doc, sort_keys=False))
    return path


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("urdf", type=Path, help="the arm's URDF (xacro already expanded)")
    parser.add_argument(
        "--package-path", type=Path, action="append", default=[], help="package:// search folder"
    )
    parser.add_argument("--out", type=Path, default=Path("urdf_cell"), help="folder to write to")
    parser.add_argument(
        "--base-xyz", type=float, nargs=3, default=[0.0, 0.0, 0.0], help="robot base in the cell"
    )
    args = parser.parse_args()
    cell_path = write_cell(args.urdf, args.package_path, args.out, args.base_xyz)
    cell = load_cell(cell_path)
    t0 = time.process_time()
    arm = cell.build_arm()
    load_s = time.process_time() - t0
    p = arm.opw
    print(f"arm        {arm.name}: joints {', '.join(arm.joint_names)}")
    print(f"           loaded in {load_s:.2f} s CPU; URDF vs OPW {arm.kinematics.fk_error_m:.1e} m")
    print("OPW        " + "  ".join(f"{k} {v:.4f}" for k, v in p.lengths().items()) + " m")
    print(f"           signs {[int(s) for s in p.sign]}  offsets {np.round(p.offset_rad, 4)}")
    print(f"home       {cell.robot.home}")
    tour = TourPlanner(Options()).plan(cell)
    gc.collect()
    tour.save(args.out / "tour.json")
    traj = np.asarray(tour.trajectory, float)
    hits = sum(arm.in_collision(q) for q in traj)
    print(f"tour       {len(tour.stops)} holes, {len(tour.left_out)} left out, "
          f"cycle {tour.cycle_time_s:.2f} s")  # fmt: skip
    for h in tour.left_out:
        print(f"  left out {h.hole_id}: {h.reason}")
    margins = f"arm {cell.robot.clearance_m * 1e3:g} mm, tool {cell.tool.clearance_m * 1e3:g} mm"
    print(
        f"check      {len(traj)} samples against the URDF's collision meshes: {hits} closer "
        f"than the clearances ({margins})"
    )
    print(f"written    {cell_path} and {args.out / 'tour.json'}")
    return 0 if not tour.left_out and hits == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
