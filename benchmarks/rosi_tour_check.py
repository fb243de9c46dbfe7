"""Evidence: the built-in IRB 2600 tour of the built-in frame against the real ROS-I meshes.

Usage: ``python benchmarks/rosi_tour_check.py ABB_EXPERIMENTAL_CHECKOUT [--tilt-deg D]``

Plans the built-in cell (``holecell plan`` defaults, or the tilt given), then checks every
trajectory sample with the ROS-Industrial collision meshes (coal BVH) placed on our links in
place of our primitives (the frames are the same: ``rosi_enclosure.py``), against the tool
shapes and every obstacle, at zero clearance. Prints, per stop, the smallest distance of the
tool to the real arm and of the real arm to the obstacles, and the samples in collision.
Skips with a message when the checkout is absent.
"""

from __future__ import annotations

import sys
import time

import numpy as np
import pinocchio as pin

from cell.config import load_builtin_cell
from planner import Options, plan_tour
from robots.collision import CollisionModel
from robots.meshes import TriangleMesh
from rosi_meshes import checkout_or_exit, load_link_meshes

MODEL = "abb_irb2600_20_165"


def real_mesh_geometry(arm, root) -> pin.GeometryModel:
    """Our arm's geometry model with every link's primitives replaced by its ROS-I mesh."""
    geom = pin.GeometryModel()
    for link, mesh in load_link_meshes(root, MODEL).items():
        fid = arm.model.getFrameId(link)
        frame = arm.model.frames[fid]
        tri = TriangleMesh(np.asarray(mesh.vertices, float), np.asarray(mesh.faces, np.int64))
        obj = pin.GeometryObject(
            f"{link}_rosi", frame.parentJoint, fid, frame.placement, tri.geometry()
        )
        geom.addGeometryObject(obj)
    return geom


def main() -> None:
    root = checkout_or_exit(sys.argv, "rosi_tour_check.py ABB_EXPERIMENTAL_CHECKOUT [--tilt-deg D]")
    tilt = float(sys.argv[sys.argv.index("--tilt-deg") + 1]) if "--tilt-deg" in sys.argv else 0.0
    cell = load_builtin_cell()
    arm = cell.build_arm()
    tour = plan_tour(cell, Options(tilt_deg=tilt))
    print(
        f"tour: {len(tour.stops)} stops, {len(tour.left_out)} left out "
        f"({', '.join(h.hole_id for h in tour.left_out) or '-'}), tilt {tilt:g} deg, "
        f"{len(tour.trajectory)} samples, clearance arm {cell.robot.clearance_m * 1e3:g} mm "
        f"tool {cell.tool.clearance_m * 1e3:g} mm"
    )
    obstacles = [s.moved(arm._T_base_cell) for s in arm.obstacles]
    real = CollisionModel(arm.model, real_mesh_geometry(arm, root), arm.tool_shapes, obstacles)
    print(f"real-mesh model: bodies touching at q=0, not checked: {real.excluded_pairs}")
    t0 = time.process_time()
    bad = [i for i, q in enumerate(tour.trajectory) if real.in_collision(q)]
    per_call_us = (time.process_time() - t0) / len(tour.trajectory) * 1e6
    print(
        f"samples in collision with the real meshes: {len(bad)} of {len(tour.trajectory)} "
        f"({per_call_us:.1f} us CPU per mesh in_collision)"
    )
    for i in bad[:10]:
        print(f"  t = {i * tour.dt:.3f} s: {real.colliding_pairs(tour.trajectory[i])[:3]}")
    names = [g.name for g in real.geom_model.geometryObjects]
    keys = []
    for pair in real.geom_model.collisionPairs:
        a, b = names[pair.first], names[pair.second]
        tool = a.startswith("tool") or b.startswith("tool")
        obst = a.startswith("obstacle") or b.startswith("obstacle")
        keys.append(
            "tool-obst"
            if tool and obst
            else "tool-arm"
            if tool
            else "arm-obst"
            if obst
            else "arm-arm"
        )

    def smallest(q: np.ndarray) -> dict[str, float]:
        pin.computeDistances(real.model, real.data, real.geom_model, real.geom_data, q)
        best = dict.fromkeys(("tool-arm", "arm-obst", "tool-obst", "arm-arm"), np.inf)
        for key, res in zip(keys, real.geom_data.distanceResults, strict=True):
            best[key] = min(best[key], res.min_distance)
        return best

    cols = ("tool-arm", "arm-obst", "tool-obst", "arm-arm")
    print(
        f"\nsmallest distance (mm) to the real meshes\n{'stop':8s} "
        + " ".join(f"{c:>10s}" for c in cols)
    )
    for stop in tour.stops:
        best = smallest(np.array(stop.q))
        print(f"{stop.hole_id:8s} " + " ".join(f"{best[c] * 1e3:10.1f}" for c in cols))
    overall = dict.fromkeys(cols, np.inf)
    for q in tour.trajectory:
        for c, d in smallest(q).items():
            overall[c] = min(overall[c], d)
    print(
        f"{'all t':8s} "
        + " ".join(f"{overall[c] * 1e3:10.1f}" for c in cols)
        + "   (every trajectory sample)"
    )


if __name__ == "__main__":
    main()
