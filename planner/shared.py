"""The seed-independent part of a plan, computed once and shared by the starts.

Viewpoints (IK candidates), the GTSP's candidate nodes and travel-time cost matrix,
the roadmap's batch collision checks and the detour costs they give do not depend on
the seed (no random choice is made there: farthest-point sampling from home,
deterministic checks). :meth:`planner.planner.TourPlanner.prepare` computes them
once; each start (:meth:`~planner.planner.TourPlanner.plan` with ``shared=``) then runs
only the seed-dependent stages — sequencing, lazy rounds, paths, timing — on its own
copy (a start changes the costs it learns). A start's tour is the same whether it
prepared the shared part itself or received it (a test holds them equal).

Shipping it costs one pickle: :func:`pack` once in the parent, :func:`unpack` in each
worker (the frame: ~3.6 MB, 657 nodes; 250 holes: the 4000 × 4000 cost matrix, 128 MB).
"""

from __future__ import annotations

import pickle
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from planner.errors import PlanningError
from planner.roadmap import Roadmap
from planner.sequence import GtspSequencer
from planner.tour import LeftOut
from planner.viewpoints import HoleCandidates


def options_key(options: Any) -> dict[str, Any]:
    """The options that shape the shared part: every setting but the seed."""
    return {k: v for k, v in asdict(options).items() if k != "seed"}


@dataclass
class SharedPlan:
    """What every start of one cell with the same options (any seed) starts from."""

    cell_sha256: str
    options: dict[str, Any]
    home: NDArray[np.float64]
    candidates: list[HoleCandidates]
    left_out: list[LeftOut]
    sequencer: GtspSequencer | None
    roadmap: Roadmap
    edge_free: dict[tuple[int, int], bool]
    collision_checks: int
    timings_s: dict[str, float] = field(default_factory=dict)
    cpu_time_s: float = 0.0  # this process's and the helper's (planner.helper)
    helper_cpu_time_s: float = 0.0

    def check(self, cell_sha256: str, options: Any) -> None:
        """Raise :class:`PlanningError` unless this was prepared for that cell and options."""
        if cell_sha256 != self.cell_sha256:
            raise PlanningError("the shared plan was prepared for another cell")
        key = options_key(options)
        diff = sorted(k for k in key if key[k] != self.options.get(k))
        if diff:
            raise PlanningError(f"the shared plan was prepared with other {', '.join(diff)}")


def pack(shared: SharedPlan) -> bytes:
    """``shared`` pickled (once, in the parent)."""
    return pickle.dumps(shared, protocol=pickle.HIGHEST_PROTOCOL)


def unpack(data: bytes | SharedPlan) -> SharedPlan:
    """A start's own copy of the shared part."""
    if isinstance(data, SharedPlan):
        return pickle.loads(pack(data))
    return pickle.loads(data)
