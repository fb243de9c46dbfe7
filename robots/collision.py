"""The collision model of an arm with its tool and the cell's obstacles.

Built on Pinocchio's :class:`GeometryModel` (coal underneath). Pairs checked:
every two robot bodies that are not adjacent in the chain (the tool counts as
a body on ``link_6``), and every robot body against every obstacle. Two robot
bodies of which any shapes already touch at q = 0 are a design overlap (the
wrist's link_6 turns inside link_4's fork, whose enclosing shapes are solid) and
are not checked against each other at all (reported in
:attr:`CollisionModel.excluded_pairs`, as MoveIt's "Default" disabled pairs); nor are the
pairs of links a user disables (``disabled``: a MoveIt SRDF's ``disable_collisions``).

Clearance (:class:`Clearance`): a pair is "in collision" when its shapes come
closer than the pair's margin, coal's ``CollisionRequest.security_margin``
(exact distance test, no shape is grown): ``robot_m`` for an arm link against
an obstacle, ``tool_m`` for the tool against an obstacle or against an arm
link; arm links among themselves get none (their shapes already enclose the
real castings, and their poses are exact kinematics, not a user's placement).
Margins rather than inflated primitives, because a margin works the same for
meshes (which cannot be inflated), differs per pair (tool, arm, self) on one
shape, and keeps the q = 0 exclusion on the true shapes.

Speed: a Pinocchio broad-phase manager culls the pairs whose boxes (grown by
half the pair's margin) do not overlap; only the rest get the exact test. Up to
:data:`NAIVE_MAX_GEOMETRIES` geometries coal's naive manager (every two boxes) is the
fastest, beyond it sweep-and-prune (:func:`broad_phase`); coal's dynamic AABB tree
spent 11 us per check in its tree traversal alone (built-in cell, ROS-I IRB 2600 meshes).
Every request starts GJK from coal's default guess, never the previous
result, and asks for the contact: with contacts off, coal 3.0 reports some
overlapping cylinder pairs as free (seen on the forearm against the upper arm).
"""

from __future__ import annotations

from collections.abc import Collection
from dataclasses import dataclass
from typing import TypeAlias

import coal
import numpy as np
import pinocchio as pin
from numpy.typing import NDArray

from robots.collision_hulls import add_hull_pairs
from robots.models import LINK_NAMES
from robots.shapes import Shape

Array = NDArray[np.float64]

#: bodies of the arm chain, in order; adjacent ones are never checked against each other
CHAIN_BODIES: tuple[str, ...] = (*LINK_NAMES, "tool")

#: up to this many geometries the naive broad phase (every two boxes) beats sweep-and-prune
#: (us per check on random configurations, the built-in cell plus copies of its obstacles,
#: naive vs SSaP: 46-53 geometries 11-24 vs 13-29, 114-121: 24-28 vs 23-41, 216-223: 60 vs
#: 38, 420-427: 220 vs 70; crossover near 115 (primitives) to 160 (mesh arm); docs/robots.md)
NAIVE_MAX_GEOMETRIES = 120


#: the broad-phase managers :func:`broad_phase` picks from
BroadPhase: TypeAlias = (
    pin.BroadPhaseManager_NaiveCollisionManager | pin.BroadPhaseManager_SSaPCollisionManager
)


def broad_phase(
    model: pin.Model, geom_model: pin.GeometryModel, geom_data: pin.GeometryData
) -> BroadPhase:
    """A broad-phase manager for ``geom_data``: naive for small cells, else sweep-and-prune.

    Both only cull on (margin-grown) boxes, so the answer is that of every pair; coal's
    dynamic AABB tree is exact too but slower here, and its array variant missed collisions
    (coal 3.0.3) and is not used.
    """
    if len(geom_model.geometryObjects) <= NAIVE_MAX_GEOMETRIES:
        return pin.BroadPhaseManager_NaiveCollisionManager(model, geom_model, geom_data)
    return pin.BroadPhaseManager_SSaPCollisionManager(model, geom_model, geom_data)


@dataclass(frozen=True)
class Clearance:
    """Margins (m) kept between the arm and obstacles (``robot_m``) and the tool and
    obstacles or arm links (``tool_m``); 0 means touching is the limit."""

    robot_m: float = 0.0
    tool_m: float = 0.0

    def __post_init__(self) -> None:
        for name in ("robot_m", "tool_m"):
            value = getattr(self, name)
            if not (np.isfinite(value) and 0.0 <= value <= 1.0):
                raise ValueError(f"clearance {name} must be in [0, 1] m, got {value!r}")

    def margin(self, body_a: str, body_b: str) -> float:
        """The margin (m) of a pair of bodies (chain body names, ``tool`` or ``obstacle``)."""
        bodies = {body_a, body_b}
        if "tool" in bodies:
            return self.tool_m
        if "obstacle" in bodies:
            return self.robot_m
        return 0.0


@dataclass(frozen=True)
class GeomInfo:
    """Bookkeeping of one geometry object: its body, a chain body or ``obstacle``."""

    name: str
    body: str


def _body_of(geom: pin.GeometryObject, model: pin.Model) -> str:
    return model.frames[geom.parentFrame].name


def _robot_geoms(model: pin.Model, geom_model: pin.GeometryModel) -> list[GeomInfo]:
    return [GeomInfo(geom.name, _body_of(geom, model)) for geom in geom_model.geometryObjects]


def _add_shape(
    geom_model: pin.GeometryModel, shape: Shape, name: str, joint: int, frame: int, M: Array
) -> None:
    obj = pin.GeometryObject(name, joint, frame, pin.SE3(M), shape.geometry())
    geom_model.addGeometryObject(obj)


class CollisionModel:
    """Geometry of arm, tool and obstacles with the pairs to check.

    Args:
        model: the Pinocchio model of the arm.
        geom_model: the arm's collision geometry (from its URDF).
        tool_shapes: tool primitives with poses relative to ``tool0``.
        obstacles: obstacle primitives with poses in the arm's base frame.
        clearance: margins kept per pair (default: none).
    """

    def __init__(
        self,
        model: pin.Model,
        geom_model: pin.GeometryModel,
        tool_shapes: list[Shape],
        obstacles: list[Shape],
        clearance: Clearance | None = None,
        disabled: Collection[tuple[str, str]] = (),
    ) -> None:
        self.model = model
        self.clearance_margins = clearance or Clearance()
        #: pairs of links never checked, given by the user (a MoveIt SRDF's disable_collisions)
        self.disabled = {frozenset(p) for p in disabled}
        self.geom_model = geom_model.copy()
        tool0 = model.getFrameId("tool0")
        link6_joint = model.frames[tool0].parentJoint
        M_joint_tool0 = model.frames[tool0].placement.homogeneous
        self.infos = _robot_geoms(model, self.geom_model)
        for i, shape in enumerate(tool_shapes):
            name = f"tool_{i}:{shape.name}"
            _add_shape(self.geom_model, shape, name, link6_joint, tool0, M_joint_tool0 @ shape.T)
            self.infos.append(GeomInfo(name, "tool"))
        universe = model.getFrameId("universe")
        for i, shape in enumerate(obstacles):
            name = f"obstacle_{i}:{shape.name}"
            _add_shape(self.geom_model, shape, name, 0, universe, shape.T)
            self.infos.append(GeomInfo(name, "obstacle"))
        self.data = model.createData()
        self.excluded_pairs: list[tuple[str, str]] = []
        self._build_pairs()

    def _candidate_pairs(self) -> list[tuple[int, int]]:
        pairs = []
        # chain position of a body: its moving joint's index (any URDF's link names); tool last
        order = {f.name: int(f.parentJoint) for f in self.model.frames}
        order["tool"] = self.model.njoints
        for i, a in enumerate(self.infos):
            for j in range(i + 1, len(self.infos)):
                b = self.infos[j]
                if a.body == "obstacle" and b.body == "obstacle":
                    continue
                both_robot = a.body != "obstacle" and b.body != "obstacle"
                if both_robot and abs(order[a.body] - order[b.body]) <= 1:
                    continue
                if both_robot and frozenset((a.body, b.body)) in self.disabled:
                    continue
                pairs.append((i, j))
        return pairs

    def _build_pairs(self) -> None:
        candidates = self._candidate_pairs()
        for i, j in candidates:
            self.geom_model.addCollisionPair(pin.CollisionPair(i, j))
        self.geom_data = pin.GeometryData(self.geom_model)
        q0 = pin.neutral(self.model)
        pin.updateGeometryPlacements(self.model, self.data, self.geom_model, self.geom_data, q0)
        touching: set[tuple[str, str]] = set()
        for k, (i, j) in enumerate(candidates):
            a, b = self.infos[i].body, self.infos[j].body
            if "obstacle" not in (a, b) and pin.computeCollision(
                self.geom_model, self.geom_data, k
            ):
                touching.add((a, b))
        drop = [
            k
            for k, (i, j) in enumerate(candidates)
            if (self.infos[i].body, self.infos[j].body) in touching
        ]
        self.excluded_pairs = sorted(touching)
        for k in reversed(drop):
            self.geom_model.removeCollisionPair(self.geom_model.collisionPairs[k])
        bodies = [info.body for info in self.infos]
        # the two links before the tool's link_6 (chain order as in _candidate_pairs)
        wrist = {f.name for f in self.model.frames if f.parentJoint in (4, 5)}
        self.mesh_pairs, self.hull_pairs = add_hull_pairs(self.geom_model, bodies, wrist)
        objects = self.geom_model.geometryObjects
        self.infos += [
            GeomInfo(objects[i].name, bodies[i]) for i in range(len(self.infos), len(bodies))
        ]
        self.geom_data = self._data_without(self.hull_pairs)
        self.broadphase = broad_phase(self.model, self.geom_model, self.geom_data)
        self._fast_broadphase = None
        if self.hull_pairs:
            self._fast_data = self._data_without(self.mesh_pairs)
            self._fast_broadphase = broad_phase(self.model, self.geom_model, self._fast_data)
            # stops at the first contact and keeps that pair's index
            self._first_hit = pin.CollisionCallBackDefault(self.geom_model, self._fast_data, True)
            self._mesh_pair_of = dict(zip(self.hull_pairs, self.mesh_pairs, strict=True))

    def _data_without(self, inactive: list[int]) -> pin.GeometryData:
        """Geometry data with its requests configured and the pairs ``inactive`` switched off."""
        geom_data = pin.GeometryData(self.geom_model)
        self._configure_requests(geom_data)
        for k in inactive:
            geom_data.deactivateCollisionPair(k)
        return geom_data

    def _configure_requests(self, geom_data: pin.GeometryData) -> None:
        # coal 3.0 misses overlapping cylinders when contacts are off (GJK stops early):
        # ask for the contact (EPA runs only on overlap) and start from the default guess.
        for pair, req in zip(
            self.geom_model.collisionPairs, geom_data.collisionRequests, strict=True
        ):
            req.enable_contact = True
            req.gjk_initial_guess = coal.GJKInitialGuess.DefaultGuess
            a, b = self.infos[pair.first].body, self.infos[pair.second].body
            req.security_margin = self.clearance_margins.margin(a, b)
        for req in geom_data.distanceRequests:
            req.gjk_initial_guess = coal.GJKInitialGuess.DefaultGuess

    def in_collision(self, q: Array) -> bool:
        """True when any checked pair comes closer than its margin at ``q`` (rad).

        A broad phase culls pairs (:func:`broad_phase`), then exact tests. With arm meshes, a
        first pass tests the tool against the links' convex hulls instead of their meshes; it
        stops at its first contact. Free there is final; a contact of a real pair is final; a
        contact of a hull pair is decided by that hull's mesh pair (a contact there is final),
        and only a hull hit whose mesh is clear runs every exact pair
        (:mod:`robots.collision_hulls`).
        """
        if self._fast_broadphase is None:
            return bool(pin.computeCollisions(self.model, self.data, self.broadphase, q, True))
        hit = self._first_hit
        if not pin.computeCollisions(self.model, self.data, self._fast_broadphase, hit, q):
            return False
        mesh_pair = self._mesh_pair_of.get(hit.collisionPairIndex)
        # the fast pass placed every geometry at q; the mesh pair's request keeps its margin
        if mesh_pair is None or pin.computeCollision(self.geom_model, self._fast_data, mesh_pair):
            return True
        return bool(pin.computeCollisions(self.model, self.data, self.broadphase, q, True))

    def in_collision_exhaustive(self, q: Array) -> bool:
        """Same answer as :meth:`in_collision`, testing every pair (reference for tests)."""
        return bool(
            pin.computeCollisions(self.model, self.data, self.geom_model, self.geom_data, q, True)
        )

    def colliding_pairs(self, q: Array) -> list[tuple[str, str]]:
        """Names of every pair in contact at ``q`` (rad)."""
        pin.computeCollisions(self.model, self.data, self.geom_model, self.geom_data, q, False)
        names = [g.name for g in self.geom_model.geometryObjects]
        out = []
        for pair, result in zip(
            self.geom_model.collisionPairs, self.geom_data.collisionResults, strict=True
        ):
            if result.isCollision():
                out.append((names[pair.first], names[pair.second]))
        return out

    def clearance(self, q: Array) -> tuple[float, tuple[str, str]]:
        """Smallest distance (m) over the checked pairs at ``q`` and the pair's names.

        Negative when shapes penetrate (coal's signed distance for primitives).
        """
        pin.computeDistances(self.model, self.data, self.geom_model, self.geom_data, q)
        distances = np.array([r.min_distance for r in self.geom_data.distanceResults])
        distances[self.hull_pairs] = np.inf  # the pre-test's pairs are not checked pairs
        k = int(np.argmin(distances))
        pair = self.geom_model.collisionPairs[k]
        names = self.geom_model.geometryObjects
        return float(distances[k]), (names[pair.first].name, names[pair.second].name)
