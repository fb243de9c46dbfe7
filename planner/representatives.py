"""Each hole's representative candidates: at most ``k`` configurations spread out in travel
time (farthest-point sampling), the nodes the GTSP search starts with
(:class:`planner.sequence.GtspSequencer`)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from planner.costs import travel_time
from planner.helper import Helper
from planner.timing import JointLimits


def representatives(
    candidates: NDArray[np.float64], k: int, anchor: NDArray[np.float64], limits: JointLimits
) -> NDArray[np.int64]:
    """Indices of at most ``k`` candidates spread out in travel time (farthest-point sampling).

    Starts from the candidate nearest ``anchor`` (rad), so the choice is deterministic.
    """
    n = len(candidates)
    if n <= k:
        return np.arange(n)
    lim = (limits.velocity, limits.acceleration, limits.jerk)
    chosen = [int(np.argmin(travel_time(candidates, anchor, *lim)))]
    nearest = travel_time(candidates, candidates[chosen[0]], *lim)
    for _ in range(k - 1):
        nxt = int(np.argmax(nearest))
        chosen.append(nxt)
        nearest = np.minimum(nearest, travel_time(candidates, candidates[nxt], *lim))
    return np.array(sorted(chosen))


def every_representatives(
    candidates: Sequence[NDArray[np.float64]],
    k: int,
    anchor: NDArray[np.float64],
    limits: JointLimits,
    helper: Helper | None = None,
) -> list[NDArray[np.int64]]:
    """:func:`representatives` of each hole's ``candidates``; with a ``helper``, those of the
    second half of the holes are chosen there meanwhile (the same indices)."""
    half = len(candidates) // 2 if helper is not None else len(candidates)
    theirs = None
    if half < len(candidates):
        assert helper is not None
        theirs = helper.submit(_representatives_of, list(candidates[half:]), k, anchor, limits)
    mine = _representatives_of(candidates[:half], k, anchor, limits)
    if theirs is None:
        return mine
    rest = list(candidates[half:])
    return mine + Helper.result(theirs, lambda: _representatives_of(rest, k, anchor, limits))


def _representatives_of(
    candidates: Sequence[NDArray[np.float64]],
    k: int,
    anchor: NDArray[np.float64],
    limits: JointLimits,
) -> list[NDArray[np.int64]]:
    return [representatives(c, k, anchor, limits) for c in candidates]
