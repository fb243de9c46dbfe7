"""Inspection viewpoints of a hole and their collision-free IK configurations.

A viewpoint puts the TCP z axis along the view direction with the hole centre
at ``standoff_m`` ahead of the TCP. The nominal view direction is the hole's
inward normal (TCP z = -normal); an optional tilt cone adds directions at
``tilt_deg`` from it. The roll about the view direction is sampled every
``roll_step_deg``. For each pose, every IK solution within the joint limits
(every branch, every J4/J6 value 2*pi apart) that is free of collision is a
candidate. Collision is checked once per distinct arm geometry (values 2*pi
apart put the arm in the same place), all of a hole's in one batch call.
"""

from __future__ import annotations

import logging
from collections import Counter
from collections.abc import Callable
from concurrent.futures import Future
from dataclasses import dataclass
from functools import partial

import numpy as np
from numpy.typing import NDArray

from planner.helper import Helper, helper_arm
from planner.protocols import ArmLike, HoleLike

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class HoleCandidates:
    """Collision-free configurations of one hole.

    ``q`` (k, 6) rad; ``branch`` (k,) IK branch ids; ``pose`` (k,) index into ``poses``
    (p, 4, 4) ``T_cell_tcp``. ``reason`` says why there is none (else ``None``).
    """

    hole_id: str
    q: NDArray[np.float64]
    branch: NDArray[np.int64]
    pose: NDArray[np.int64]
    poses: NDArray[np.float64]
    reason: str | None

    @property
    def ok(self) -> bool:
        """True when at least one candidate exists."""
        return len(self.q) > 0


def _basis(z: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    ref = np.array([1.0, 0.0, 0.0]) if abs(z[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    x = ref - z * (ref @ z)
    x /= np.linalg.norm(x)
    return x, np.cross(z, x)


def view_directions(
    normal: NDArray[np.float64], tilt_deg: float, azimuths: int
) -> NDArray[np.float64]:
    """Unit view directions (cell frame): ``-normal`` and, if tilted, a ring on the cone."""
    z = -np.asarray(normal, dtype=float)
    z /= np.linalg.norm(z)
    dirs = [z]
    if tilt_deg > 0:
        x, y = _basis(z)
        tilt = np.radians(tilt_deg)
        for k in range(azimuths):
            phi = 2 * np.pi * k / azimuths
            dirs.append(np.cos(tilt) * z + np.sin(tilt) * (np.cos(phi) * x + np.sin(phi) * y))
    return np.array(dirs)


def viewpoint_poses(
    position_m: NDArray[np.float64],
    normal: NDArray[np.float64],
    standoff_m: float,
    roll_step_deg: float,
    tilt_deg: float = 0.0,
    tilt_azimuths: int = 6,
) -> NDArray[np.float64]:
    """Every sampled ``T_cell_tcp`` (p, 4, 4) viewing the hole centre from ``standoff_m``."""
    rolls = np.radians(np.arange(0.0, 360.0 - 1e-9, roll_step_deg))
    c, s = np.cos(rolls)[:, None], np.sin(rolls)[:, None]
    dirs = view_directions(normal, tilt_deg, tilt_azimuths)
    poses = np.zeros((len(dirs), len(rolls), 4, 4))
    poses[..., 3, 3] = 1.0
    for T, z in zip(poses, dirs, strict=True):  # every roll of a direction at once
        x0, y0 = _basis(z)
        T[:, :3, 0] = c * x0 + s * y0
        T[:, :3, 1] = -s * x0 + c * y0
        T[:, :3, 2] = z
        T[:, :3, 3] = np.asarray(position_m, dtype=float) - standoff_m * z
    return poses.reshape(-1, 4, 4)


def _describe_collisions(arm: ArmLike, samples: list[NDArray[np.float64]]) -> str:
    pairs: Counter[tuple[str, str]] = Counter()
    for q in samples[:5]:
        pairs.update(arm.colliding_pairs(q))
    if not pairs:
        return "in collision from every viewpoint"
    (a, b), _ = pairs.most_common(1)[0]
    return f"in collision from every viewpoint (e.g. {a} with {b})"


def _distinct_rows(A: NDArray[np.float64]) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """``np.unique(A, axis=0, return_index=True, return_inverse=True)``'s index and inverse
    (distinct rows in lexicographic order, each one's first occurrence), in a fifth of the
    time on a pose's handful of IK solutions."""
    order = np.lexsort(A.T[::-1])  # stable: equal rows keep their order
    S = A[order]
    new = np.ones(len(A), dtype=bool)
    new[1:] = np.any(S[1:] != S[:-1], axis=1)
    inverse = np.empty(len(A), dtype=np.int64)
    inverse[order] = np.cumsum(new) - 1
    return order[new], inverse


def _in_collision_each(arm: ArmLike, Q: NDArray[np.float64]) -> NDArray[np.bool_]:
    """``arm.in_collision`` of each row of ``Q``: one batch call where the arm offers it
    (``robots.Arm.in_collision_each``, the same answers), else one at a time."""
    each = getattr(arm, "in_collision_each", None)
    if each is not None:
        return np.asarray(each(Q), dtype=bool).reshape(len(Q))
    return np.array([arm.in_collision(q) for q in Q], dtype=bool)


def hole_candidates(
    arm: ArmLike,
    hole: HoleLike,
    standoff_m: float,
    roll_step_deg: float,
    tilt_deg: float = 0.0,
    tilt_azimuths: int = 6,
    known_empty: int = 0,
) -> HoleCandidates:
    """Collision-free IK configurations of every viewpoint of ``hole`` (see module docstring).

    ``known_empty``: the first poses known to have no collision-free configuration (the
    axis poses, before a fallback cone) are not solved again (the same candidates; only the
    ``reason`` of an empty result leaves them out)."""
    poses = viewpoint_poses(
        hole.position_m, hole.normal, standoff_m, roll_step_deg, tilt_deg, tilt_azimuths
    )
    ik_reasons: Counter[str] = Counter()
    sols, branches, pose_of = [], [], []
    many = getattr(arm, "ik_many", None)  # every pose in one call (robots.Arm.ik_many)
    results = many(poses[known_empty:]) if many is not None else None
    for p in range(known_empty, len(poses)):
        result = results[p - known_empty] if results is not None else arm.ik(poses[p])
        if not result.ok:
            ik_reasons[result.reason or "no IK solution"] += 1
            continue
        sols.append(result.solutions)
        branches.append(np.asarray(result.branches, dtype=np.int64))
        pose_of.append(np.full(len(result.solutions), p, dtype=np.int64))
    S = np.vstack(sols) if sols else np.zeros((0, 6))
    B = np.concatenate(branches) if branches else np.zeros(0, np.int64)
    P = np.concatenate(pose_of) if pose_of else np.zeros(0, np.int64)
    # each pose's distinct arm geometries (values 2*pi apart: the same), pose by pose in
    # lexicographic order: the pose is the first key
    wrapped = np.round((S + np.pi) % (2 * np.pi) - np.pi, 9)
    first, inverse = _distinct_rows(np.column_stack([P.astype(float), wrapped]))
    hit = _in_collision_each(arm, S[first])
    keep = ~hit[inverse]
    q = S[keep]
    reason = None
    if len(q) == 0:
        if len(S):
            reason = _describe_collisions(arm, list(S[first[hit]]))
        else:
            reason = ", ".join(r for r, _ in ik_reasons.most_common()) or "no IK solution"
    log.debug("hole %s: %d poses, %d candidates", hole.id, len(poses), len(q))
    return HoleCandidates(
        hole_id=hole.id, q=q, branch=B[keep], pose=P[keep], poses=poses, reason=reason
    )


@dataclass(frozen=True)
class ViewSettings:
    """The viewpoint settings of :class:`planner.options.Options` (deg, m)."""

    standoff_m: float
    roll_step_deg: float
    tilt_deg: float
    tilt_azimuths: int
    fallback_tilt_deg: float


def hole_viewpoints(arm: ArmLike, hole: HoleLike, s: ViewSettings) -> tuple[HoleCandidates, bool]:
    """:func:`hole_candidates` of ``hole``; when it has none and the fallback cone is wider,
    those of the fallback cone if any. Returns them and whether the fallback gave them."""
    c = hole_candidates(arm, hole, s.standoff_m, s.roll_step_deg, s.tilt_deg, s.tilt_azimuths)
    if not c.ok and s.fallback_tilt_deg > s.tilt_deg:
        # the first poses of both cones (the view along the axis) gave no candidate
        axis = len(c.poses) // (1 + (s.tilt_azimuths if s.tilt_deg > 0 else 0))
        tilted = hole_candidates(
            arm, hole, s.standoff_m, s.roll_step_deg, s.fallback_tilt_deg, s.tilt_azimuths, axis
        )
        if tilted.ok:
            return tilted, True
    return c, False


#: holes per chunk of work handed to the helper process (:mod:`planner.helper`)
CHUNK = 6


@dataclass
class _Hole:
    """What a hole's viewpoints need of it (sent to the helper process)."""

    id: str
    position_m: NDArray[np.float64]
    normal: NDArray[np.float64]


def _chunk_here(
    arm: ArmLike, holes: list[HoleLike], s: ViewSettings
) -> list[tuple[HoleCandidates, bool]]:
    return [hole_viewpoints(arm, h, s) for h in holes]


def _helper_chunk(holes: list[_Hole], s: ViewSettings) -> list[tuple[HoleCandidates, bool]]:
    """:func:`hole_viewpoints` of ``holes`` (in the helper process)."""
    return [hole_viewpoints(helper_arm(), h, s) for h in holes]


def all_hole_candidates(
    arm: ArmLike,
    holes: list[HoleLike],
    s: ViewSettings,
    helper: Helper | None = None,
    progress: Callable[[int], None] | None = None,
    meanwhile: Callable[[], None] | None = None,
) -> list[tuple[HoleCandidates, bool]]:
    """:func:`hole_viewpoints` of every hole, in order. With a ``helper``, it takes chunks
    of ``CHUNK`` holes from the back while this process works from the front; a chunk it
    has not started when this process reaches it is done here (the same results, whoever
    computes them). ``progress(done)`` after each hole; ``meanwhile()``: other work for
    this process, done first when there is a helper (which then takes more chunks)."""
    out: list[tuple[HoleCandidates, bool] | None] = [None] * len(holes)
    done = 0
    chunks = [(lo, min(lo + CHUNK, len(holes))) for lo in range(0, len(holes), CHUNK)]
    futures: dict[int, Future[list[tuple[HoleCandidates, bool]]]] = {}
    if helper is not None:
        for k in range(len(chunks) - 1, 0, -1):  # last chunk first; the first stays here
            lo, hi = chunks[k]
            sent = [
                _Hole(h.id, np.asarray(h.position_m), np.asarray(h.normal)) for h in holes[lo:hi]
            ]
            futures[k] = helper.submit(_helper_chunk, sent, s)
        if meanwhile is not None:
            meanwhile()
    for k, (lo, hi) in enumerate(chunks):
        f = futures.get(k)
        if f is not None and not f.cancel():
            break  # the helper has it (and every chunk after it)
        for i in range(lo, hi):
            out[i] = hole_viewpoints(arm, holes[i], s)
            done += 1
            if progress is not None:
                progress(done)
    for k, f in futures.items():
        if not f.cancelled():
            lo, hi = chunks[k]
            here = partial(_chunk_here, arm, holes[lo:hi], s)
            out[lo:hi] = Helper.result(f, here)
            done += hi - lo
            if progress is not None:
                progress(done)
    assert all(x is not None for x in out)
    return [x for x in out if x is not None]
