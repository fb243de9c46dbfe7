"""A planned route (the stop configurations of the tour's holes in order) and the tour's stops
and timeline from it and its segments."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from planner.protocols import ArmLike
from planner.segments import Segment
from planner.timing import TimedMotion
from planner.tour import Stop, pose_dict
from planner.trajectory import Dwell
from planner.viewpoints import HoleCandidates


@dataclass(frozen=True)
class Route:
    """Hole ids, stop configurations (n, dof) rad, IK branch per stop, candidates per hole."""

    hole_ids: list[str]
    q: NDArray[np.float64]  # (n, dof) stop configurations in order
    branch: list[int]
    candidates: list[HoleCandidates]


def route_stops(
    arm: ArmLike, route: Route, segments: list[Segment], dwell_s: float
) -> tuple[list[Stop], list[TimedMotion | Dwell], float]:
    """The tour's stops (tcp pose, arrival time s, dwell ``dwell_s`` s), its timeline of motions
    and dwells, and the cycle time (s), from the route and its segments (home to home)."""
    timeline: list[TimedMotion | Dwell] = []
    stops: list[Stop] = []
    clock = 0.0
    for k, seg in enumerate(segments):
        timeline.append(seg.motion)
        clock += seg.motion.duration
        if k == len(route.hole_ids):
            break
        q = route.q[k]
        T = arm.fk(q, "tcp")
        pose = pose_dict(T)
        stops.append(
            Stop(
                route.hole_ids[k],
                tuple(float(v) for v in q),
                clock,
                dwell_s,
                pose,
                route.branch[k],
            )
        )
        timeline.append(Dwell(q, dwell_s))
        clock += dwell_s
    return stops, timeline, clock
