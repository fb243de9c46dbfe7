"""Where a further reference target would help: candidate places scored by the designed plan.

A reference target needs a rigid place that exists in the cell: the candidates are points on a
grid on the top faces of the environment's upright boxes (tables, fixture plates), 1 mm above
the face and ``edge_m`` in from its edges. Each is scored by the reference plan designed for the
stops with three more views allowed (:mod:`robots.thermal.design`, as the reference plan), against
the same number of views of the present targets: a target pays only if it beats more views of
what is there. Line of sight from the head to the target is not checked beyond the head's own
collision shapes.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import NDArray

from cell.config import CellConfig
from cell.errors import CellError
from robots.thermal.design import DesignOptions, candidate_views, design_views

#: a box counts as upright when its z axis is within this of the vertical (cos)
UPRIGHT_COS = 1.0 - 1e-6


@dataclass(frozen=True)
class TargetScore:
    """A candidate place (cell frame, m) and the predicted RMS at the stops with it (m)."""

    position_m: tuple[float, float, float]
    predicted_rms_m: float
    views_of_it: int


def top_face_points(
    cell: CellConfig, spacing_m: float = 0.1, edge_m: float = 0.03
) -> list[NDArray[np.float64]]:
    """Grid points (cell frame, m) on the top faces of the environment's upright boxes."""
    out = []
    for spec in cell.environment.obstacles:
        if spec.box is None:
            continue
        T = spec.pose.matrix()
        if T[2, 2] < UPRIGHT_COS:
            continue
        sx, sy, sz = spec.box.size
        for x in np.arange(-sx / 2 + edge_m, sx / 2 - edge_m + 1e-9, spacing_m):
            for y in np.arange(-sy / 2 + edge_m, sy / 2 - edge_m + 1e-9, spacing_m):
                out.append((T @ np.array([x, y, sz / 2 + 0.001, 1.0]))[:3])
    return out


def suggest_targets(
    cell: CellConfig,
    stops_q: NDArray[np.float64],
    options: DesignOptions | None = None,
    spacing_m: float = 0.1,
) -> tuple[float, list[TargetScore]]:
    """``(RMS with three more views of the present targets, scores best first)`` (m): every
    :func:`top_face_points` place with a reachable, collision-free view, scored by the design
    with three more views than ``options`` (default three per present target)."""
    o = options or DesignOptions()
    more = replace(o, n_views=(o.n_views or 3 * len(cell.reference_targets)) + 3)
    points = top_face_points(cell, spacing_m)
    if not points:
        raise CellError(f"cell {cell.name!r}: no upright environment box to place a target on")
    arm = cell.build_arm()
    geometry = (arm.dh, arm.lower, arm.upper, cell.T_cell_base(), cell.T_tool0_tcp())
    free = {"accept": lambda q: not arm.in_collision(q), "rest_q": cell.home_q()}
    targets = {r.id: (r.position, r.normal) for r in cell.reference_targets}
    base, _ = candidate_views(*geometry, targets, cell.tool.standoff_m, more, **free)
    frames = (arm.dh, cell.T_cell_base(), cell.T_tool0_tcp())
    baseline = design_views(*frames, base, stops_q, more).predicted_rms_m
    scores = []
    for p in points:
        new, _ = candidate_views(*geometry, {"NEW": (p, (0.0, 0.0, 1.0))}, cell.tool.standoff_m,
                                 more, **free)  # fmt: skip
        if not new:
            continue
        d = design_views(*frames, base + new, stops_q, more)
        used = sum(v.target_id == "NEW" for v in d.views)
        scores.append(TargetScore(tuple(float(v) for v in p), d.predicted_rms_m, used))
    return baseline, sorted(scores, key=lambda s: s.predicted_rms_m)
