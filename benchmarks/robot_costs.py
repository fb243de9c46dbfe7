"""Cost of the foundation's hot calls on the built-in cell, from Python, one core.

Prints a table: a collision check of one configuration (free and all random
configurations), the clearance query, forward kinematics, and all IK branches
of one pose, for each built-in model. Targets: collision check <= 30 us on the
default cell, all IK branches <= 100 us.

    .venv/bin/python benchmarks/robot_costs.py [--n 5000]
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Callable

import numpy as np

from cell.config import load_builtin_cell
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


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=5000, help="calls per measurement")
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


if __name__ == "__main__":
    main()
