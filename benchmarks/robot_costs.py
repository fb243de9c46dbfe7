"""Cost of the foundation's hot calls on the built-in cell, from Python, one core.

Prints a table: a collision check of one configuration (free and all random
configurations), the clearance query, forward kinematics, and all IK branches
of one pose, for each built-in model. Targets: collision check <= 30 us on the
default cell, all IK branches <= 100 us.

Then the same cell with an arm given by a URDF with collision meshes: arm load
time (<= 1 s CPU), ``in_collision`` (<= 30 us, with the cell's clearances) and
IK of the URDF-derived OPW model (<= 100 us). ``--mesh-urdf`` names that URDF (e.g.
the ROS-Industrial IRB 2600, expanded from xacro, with ``--package-path`` for its package://
meshes); without it, the built-in IRB 2600 with every primitive turned into a
triangle mesh (generated here, in a temporary folder) is used. The table says
which. The mesh check is cross-checked against the exhaustive pair test.

Every ``in_collision`` row checks the whole cell: the arm against itself, the tool (stereo head
and cameras) against the arm, arm and tool against the built-in frame's 34 obstacles, with the
cell's clearances (arm 10 mm, tool 5 mm). "Random configurations" are 5000 (``--n``) drawn
uniformly within the arm's joint limits (for a URDF, its own limits, not narrowed by a cell;
the ROS-I IRB 2600's J2 is [-2.705, 1.658] rad), about a third of them in collision; "free"
rows use the collision-free ones among them.

    .venv/bin/python benchmarks/robot_costs.py [--n 5000] [--mesh-urdf U --package-path P]
"""

from __future__ import annotations

import argparse
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

from cell.config import load_builtin_cell
from mesh_arm import meshed_builtin_urdf
from robots import MODELS, Arm


def _time_per_call(
    fn: Callable[[np.ndarray], object], inputs: np.ndarray, repeats: int = 5
) -> float:
    """Best-of-``repeats`` mean CPU time per call (s) of this process.

    CPU time, not wall time: the machines are shared, and other processes'
    load would otherwise be counted as ours.
    """
    best = float("inf")
    for _ in range(repeats):
        t0 = time.process_time()
        for x in inputs:
            fn(x)
        best = min(best, (time.process_time() - t0) / len(inputs))
    return best


def _mesh_rows(args: argparse.Namespace, rng: np.random.Generator) -> list[tuple]:
    """Load, collision and IK rows for the cell with a mesh arm."""
    cfg = load_builtin_cell()
    tmp = tempfile.TemporaryDirectory()
    if args.mesh_urdf:
        urdf, source = Path(args.mesh_urdf), f"{Path(args.mesh_urdf).name} (its own meshes)"
    else:
        urdf = meshed_builtin_urdf(Path(tmp.name))
        source = "built-in IRB 2600, primitives as generated meshes"
    loads = []
    for _ in range(3):
        t0 = time.process_time()
        arm = Arm(urdf, T_cell_base=cfg.T_cell_base(), package_paths=args.package_path)
        loads.append(time.process_time() - t0)
    arm.set_tool(cfg.T_tool0_tcp(), cfg.tool_shapes())
    arm.add_obstacles(cfg.obstacle_shapes())
    arm.set_clearance(cfg.robot.clearance_m, cfg.tool.clearance_m)  # as the primitive rows
    t0 = time.process_time()
    _ = arm.collision
    build_s = time.process_time() - t0
    n_tris = sum(
        getattr(g.geometry, "num_tris", 0) for g in arm.collision.geom_model.geometryObjects
    )
    qs = rng.uniform(arm.lower, arm.upper, (args.n, 6))
    verdict = [arm.in_collision(q) for q in qs]
    agree = sum(
        v == arm.collision.in_collision_exhaustive(q) for v, q in zip(verdict, qs, strict=True)
    )
    free = qs[~np.array(verdict)]
    poses = np.array([arm.fk(q) for q in rng.uniform(arm.lower, arm.upper, (args.n, 6))])
    print(f"\nmesh arm: {source}; {n_tris} triangles; clearance arm "
          f"{cfg.robot.clearance_m * 1e3:g} mm, tool {cfg.tool.clearance_m * 1e3:g} mm; broad "
          f"phase agrees with every pair on {agree}/{len(qs)}; {len(free)} free")  # fmt: skip
    tmp.cleanup()
    return [
        ("arm load (URDF, meshes, OPW check), CPU", min(loads), 1e6),
        ("collision model build (pairs, q=0 check), CPU", build_s, None),
        ("in_collision, mesh arm, free configurations", _time_per_call(arm.in_collision, free), 30),
        ("in_collision, mesh arm, random configurations", _time_per_call(arm.in_collision, qs), 30),
        ("ik, all branches: URDF-derived OPW", _time_per_call(arm.ik, poses), 100),
    ]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=5000, help="calls per measurement")
    parser.add_argument("--mesh-urdf", default=None, help="URDF with collision meshes")
    parser.add_argument(
        "--package-path", action="append", default=[], help="package:// search folder"
    )
    args = parser.parse_args()
    rng = np.random.default_rng(0)

    cfg = load_builtin_cell()
    arm = cfg.build_arm()
    qs = rng.uniform(arm.lower, arm.upper, (args.n, 6))
    free = np.array([q for q in qs if not arm.in_collision(q)])
    n_geoms = len(arm.collision.geom_model.geometryObjects)
    n_pairs = len(arm.collision.geom_model.collisionPairs)
    print(
        f"built-in cell: {len(arm.obstacles)} obstacles, {n_geoms} geometries, "
        f"{n_pairs} pairs checked"
    )
    print(f"{'call':44s} {'us/call':>9s} {'target':>8s}")
    rows = [
        ("in_collision, collision-free configurations", _time_per_call(arm.in_collision, free), 30),
        ("in_collision, random configurations", _time_per_call(arm.in_collision, qs), 30),
        (
            "in_collision, every pair (no broad phase)",
            _time_per_call(arm.collision.in_collision_exhaustive, qs),
            None,
        ),
        ("clearance (all pair distances)", _time_per_call(arm.clearance, qs[:500]), None),
        ("fk tcp (Pinocchio)", _time_per_call(arm.fk, qs), None),
    ]
    for name, spec in sorted(MODELS.items()):
        model_arm = Arm(name)
        poses = np.array(
            [model_arm.fk(q) for q in rng.uniform(model_arm.lower, model_arm.upper, (args.n, 6))]
        )
        rows.append((f"ik, all branches: {spec.title}", _time_per_call(model_arm.ik, poses), 100))
    for label, seconds, target in rows:
        target_text = f"<= {target}" if target else ""
        print(f"{label:44s} {seconds * 1e6:9.1f} {target_text:>8s}")
    print(f"({len(free)} of {len(qs)} random configurations are collision-free)")
    mesh_rows = _mesh_rows(args, rng)
    print(f"{'call':48s} {'us/call':>10s} {'target':>10s}")
    for label, seconds, target in mesh_rows:
        target_text = f"<= {target:g}" if target else ""
        print(f"{label:48s} {seconds * 1e6:10.1f} {target_text:>10s}")


if __name__ == "__main__":
    main()
