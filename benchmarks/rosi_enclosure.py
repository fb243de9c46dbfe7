"""Evidence: how far the ROS-I collision meshes stick out of our primitives, per link (q = 0).

Usage: ``python benchmarks/rosi_enclosure.py ABB_EXPERIMENTAL_CHECKOUT [URDF_DIR]``

For each built-in model: first the frames (the ROS-I xacro's joint origins and axes against
ours, and its collision origins, which must be identity for the meshes to be in our link
frames as they are); then the mesh vertices plus 20000 surface samples
per link are tested against the union of that link's primitives in ``URDF_DIR`` (default: the
shipped ``robots/urdf``). Prints the protrusion (mm), the volume of the primitives' union
(Monte Carlo) and of the mesh's hull (L). Skips without a checkout.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pinocchio as pin

from rosi_meshes import (
    ROSI_MODELS,
    checkout_or_exit,
    frame_differences,
    load_link_meshes,
    protrusion,
    surface_points,
    union_volume,
)

SHIPPED = Path(__file__).resolve().parent.parent / "robots" / "urdf"


def main() -> None:
    root = checkout_or_exit(sys.argv, "rosi_enclosure.py ABB_EXPERIMENTAL_CHECKOUT [URDF_DIR]")
    urdf_dir = Path(sys.argv[2]) if len(sys.argv) > 2 else SHIPPED
    print(f"primitives from {urdf_dir}")
    for model in ROSI_MODELS:
        joint_diff, collision_offset = frame_differences(root, model)
        print(
            f"{model}: ROS-I joint origins and axes vs ours: largest difference {joint_diff:g}; "
            f"largest collision origin offset {collision_offset:g} (0: meshes in our link frames)"
        )
    print(f"{'model':20s} {'link':10s} {'protrusion mm':>14s} {'union L':>8s} {'hull L':>7s}")
    for model in ROSI_MODELS:
        m, geom, _ = pin.buildModelsFromUrdf(str(urdf_dir / f"{model}.urdf"))
        tot_p = tot_h = 0.0
        for link, mesh in load_link_meshes(root, model).items():
            fid = m.getFrameId(link)
            prims = [
                (g.geometry, g.placement.homogeneous)
                for g in geom.geometryObjects
                if g.parentFrame == fid
            ]
            out = protrusion(surface_points(mesh), prims) if prims else np.array([np.inf])
            vol = union_volume(prims)
            hull = float(mesh.convex_hull.volume)
            tot_p, tot_h = tot_p + vol, tot_h + hull
            print(
                f"{model:20s} {link:10s} {out.max() * 1e3:14.1f} {vol * 1e3:8.1f} {hull * 1e3:7.1f}"
            )
        print(f"{model:20s} {'all':10s} {'':14s} {tot_p * 1e3:8.1f} {tot_h * 1e3:7.1f}")


if __name__ == "__main__":
    main()
