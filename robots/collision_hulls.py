"""Convex-hull pre-test of the tool against an arm's mesh links (exact answer kept).

The tool sits next to the wrist's link meshes at every configuration, so coal's AABB tree never
culls those pairs and each check walks the mesh BVH down to triangles near the tool (13 of
about 35 us per check for the ROS-I IRB 2600's link_4 against the stereo head). A link mesh
lies inside its convex hull, so a tool shape farther than the margin from the hull is farther
from the mesh: :func:`add_hull_pairs` adds each such link's hull (coal, qhull) as a geometry of
the same link, paired with the tool shapes (wrist links only: the broad phase culls the
others), for a fast pass in place of the tool-vs-mesh pairs: its "free" is final, a contact of a
real pair is final, and a contact of a hull pair is decided by that hull's mesh pair (every exact
pair runs only when that mesh is clear: :meth:`robots.collision.CollisionModel.in_collision`).
"""

from __future__ import annotations

import coal
import pinocchio as pin

HULL_SUFFIX = "#hull"


def add_hull_pairs(
    geom_model: pin.GeometryModel, bodies: list[str], wrist: set[str]
) -> tuple[list[int], list[int]]:
    """Add a hull geometry per wrist mesh paired with a tool shape, and its pairs.

    Args:
        geom_model: the model with its checked pairs; extended in place.
        bodies: the body of every geometry object (``tool``, ``obstacle`` or a link name);
            extended in place with the hulls' bodies.
        wrist: the links next to the tool (link_4, link_5), whose pairs with the tool the
            broad phase cannot cull; the other links' pairs are left as they are.

    Returns:
        (indices of the tool-vs-mesh pairs, indices of the tool-vs-hull pairs added).
    """
    objects = geom_model.geometryObjects
    mesh_pairs: list[int] = []
    hull_of: dict[int, int] = {}
    new_pairs: list[tuple[int, int]] = []
    for k, pair in enumerate(geom_model.collisionPairs):
        a, b = pair.first, pair.second
        if bodies[a] == "tool":
            a, b = b, a
        if bodies[b] != "tool" or bodies[a] not in wrist:
            continue
        mesh = objects[a].geometry
        if not isinstance(mesh, coal.BVHModelBase):
            continue
        if a not in hull_of:
            mesh.buildConvexHull(True, "Qt")
            src = objects[a]
            hull = pin.GeometryObject(
                src.name + HULL_SUFFIX, src.parentJoint, src.parentFrame, src.placement, mesh.convex
            )
            hull_of[a] = geom_model.addGeometryObject(hull)
            bodies.append(bodies[a])
        mesh_pairs.append(k)
        new_pairs.append((hull_of[a], b))
    first = len(geom_model.collisionPairs)
    for a, b in new_pairs:
        geom_model.addCollisionPair(pin.CollisionPair(min(a, b), max(a, b)))
    return mesh_pairs, list(range(first, first + len(new_pairs)))
