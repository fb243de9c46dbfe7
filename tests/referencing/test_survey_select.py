"""Choosing the survey's views: the fewest of the planned views that see every marker in enough
views from directions well apart, in one piece."""

from __future__ import annotations

import math

import numpy as np

from cell.camera import cell_stereo
from cell.config import load_builtin_cell
from cell.config.markers import marker_in_cell
from cell.referencing.survey.plan import survey_views
from cell.referencing.survey.select import SelectOptions, select_cell_views, select_views
from cell.referencing.visibility import seen_each


def seen(stereo, T, P, N):
    left, right = seen_each(stereo, T, P, N)
    return left & right


def seen_either(stereo, T, P, N):
    return np.logical_or(*seen_each(stereo, T, P, N))


def _markers(cell):
    placed = [marker_in_cell(m, cell.T_cell_part()) for m in cell.reference_markers]
    return np.array([p for p, _ in placed]), np.array([n for _, n in placed])


def test_the_builtin_survey_keeps_every_markers_views_and_angles() -> None:
    cell = load_builtin_cell()
    stereo = cell_stereo(cell)
    planned = survey_views(cell, stereo)
    o = SelectOptions()
    chosen = select_cell_views(cell, stereo, planned, o)
    assert len(chosen) < len(planned) / 2
    P, N = _markers(cell)
    sees_all = np.array([seen(stereo, T, P, N) for _, T in planned])
    either = np.array([seen_either(stereo, T, P, N) for _, T in planned])
    sees_all[either.sum(axis=1) < o.min_markers] = False  # views that cannot be located
    sees = np.array([seen(stereo, T, P, N) for _, T in chosen])
    possible = np.minimum(sees_all.sum(axis=0), o.min_views)
    assert (sees.sum(axis=0) >= possible).all()
    centres = np.array([T[:3, 3] for _, T in chosen])
    for j in np.flatnonzero(sees_all.any(axis=0)):
        rays = centres[sees[:, j]] - P[j]
        rays /= np.linalg.norm(rays, axis=1, keepdims=True)
        widest = math.acos(float(np.clip((rays @ rays.T).min(), -1.0, 1.0)))
        assert widest >= math.radians(20.0), (cell.reference_markers[j].id, widest)
    assert [v for v, _ in chosen] == [v for v, _ in planned if v in dict(chosen)]  # in order


def test_a_repeated_view_is_taken_once_and_a_second_direction_is_sought() -> None:
    cell = load_builtin_cell()
    stereo = cell_stereo(cell)
    planned = survey_views(cell, stereo)
    P, N = _markers(cell)
    counts = np.array([seen(stereo, T, P, N).sum() for _, T in planned])
    name, T = planned[int(np.argmax(counts))]
    sees = seen(stereo, T, P, N)
    twice = [(name, T), (name + "-again", T.copy())]
    one = select_views(twice, stereo, P[sees], N[sees], SelectOptions(min_views=1))
    assert [v for v, _ in one] == [name]
    # two views, same direction: the second adds a view but never the angle
    both = select_views(twice, stereo, P[sees], N[sees], SelectOptions(min_views=2))
    assert len(both) == 2
