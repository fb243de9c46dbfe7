"""The survey's refusals, checked before any adjustment: each names the marker or the pieces.

- a view that sees fewer than :data:`MIN_MARKERS_PER_VIEW` markers (in either camera), or only
  markers on one line (a row on the table: the view could turn about it), cannot be located and
  is left out (said in the result, not refused);
- a marker seen in fewer than :data:`MIN_VIEWS_PER_MARKER` of the remaining views;
- a marker whose rays meet at less than :data:`MIN_INTERSECTION_RAD` (the widest angle between
  the views' left-camera centres as seen from the marker): its depth is weak;
- a network in more than one piece (views and markers linked by an observation): each piece
  would have its own datum.
"""

from __future__ import annotations

import math

import numpy as np

from cell.referencing.errors import SurveyRefusedError
from cell.referencing.observations import MarkerView

MIN_MARKERS_PER_VIEW = 4
MIN_VIEWS_PER_MARKER = 3
MIN_INTERSECTION_RAD = math.radians(20.0)
#: a view's markers are "on one line" when their scatter across the line is below this share of
#: their scatter along it
MIN_SPREAD_RATIO = 0.1


def usable_views(
    views: list[MarkerView], marker_ids: list[str], nominal: np.ndarray
) -> tuple[list[MarkerView], list[str]]:
    """The views that see at least :data:`MIN_MARKERS_PER_VIEW` of ``marker_ids`` (nominal
    centres (n, 3)) in their two cameras together, not all on one line; and the ids of those
    left out."""
    index = {m: k for k, m in enumerate(marker_ids)}
    keep, dropped = [], []
    for v in views:
        rows = [index[m] for m in v.either() if m in index]
        ok = len(rows) >= MIN_MARKERS_PER_VIEW
        if ok:
            sv = np.linalg.svd(nominal[rows] - nominal[rows].mean(axis=0), compute_uv=False)
            ok = bool(sv[1] >= MIN_SPREAD_RATIO * sv[0])
        (keep if ok else dropped).append(v)
    return keep, [v.view_id for v in dropped]


def check_network(views: list[MarkerView], marker_ids: list[str], nominal: np.ndarray) -> None:
    """Raise :class:`SurveyRefusedError` for the first refusal of the module doc."""
    index = {m: k for k, m in enumerate(marker_ids)}
    seen_by: list[list[int]] = [[] for _ in marker_ids]
    for v, view in enumerate(views):
        for m in view.either():
            if m in index:
                seen_by[index[m]].append(v)
    for k, m in enumerate(marker_ids):
        if len(seen_by[k]) < MIN_VIEWS_PER_MARKER:
            n = len(seen_by[k])
            need = MIN_VIEWS_PER_MARKER
            raise SurveyRefusedError(f"marker {m}", f"seen in {n} views, at least {need} needed")
    centres = np.array([v.T_cell_left_prior[:3, 3] for v in views])
    for k, m in enumerate(marker_ids):
        rays = centres[seen_by[k]] - nominal[k]
        rays /= np.linalg.norm(rays, axis=1, keepdims=True)
        widest = math.acos(float(np.clip((rays @ rays.T).min(), -1.0, 1.0)))
        if widest < MIN_INTERSECTION_RAD:
            raise SurveyRefusedError(
                f"marker {m}",
                f"its rays meet at {math.degrees(widest):.1f} "
                f"deg at most, {math.degrees(MIN_INTERSECTION_RAD):.0f} deg "
                "needed",
            )
    pieces = network_pieces(seen_by, len(views))
    if len(pieces) > 1:
        names = ", ".join(f"{{{marker_ids[p[0]]}, ... {len(p)} markers}}" for p in pieces[:3])
        raise SurveyRefusedError("network", f"in {len(pieces)} pieces that no view links: {names}")


def network_pieces(seen_by: list[list[int]], n_views: int) -> list[list[int]]:
    """Markers grouped by the connected pieces of the view-marker graph."""
    parent = list(range(len(seen_by) + n_views))

    def find(a: int) -> int:
        while parent[a] != a:
            parent[a] = parent[parent[a]]
            a = parent[a]
        return a

    for k, vs in enumerate(seen_by):
        for v in vs:
            parent[find(k)] = find(len(seen_by) + v)
    groups: dict[int, list[int]] = {}
    for k in range(len(seen_by)):
        groups.setdefault(find(k), []).append(k)
    return sorted(groups.values(), key=len, reverse=True)
