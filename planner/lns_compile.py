"""Compile (or load from Numba's cache) every kernel of the GTSP search up front:
:mod:`planner.lns_kernel` and :mod:`planner.lns_near`, so that a search's work limits and
time cap (:mod:`planner.lns`) never count the compiler."""

from __future__ import annotations

import numpy as np

from planner.lns_kernel import improve_path, insert, layered
from planner.lns_near import improve_path_near, insert_near


def compile_kernels() -> None:
    """Compile (or load from the cache) every kernel on a tiny problem, so that a search's
    work limits and time cap (:mod:`planner.lns`) never count the compiler; fast after
    the first call in a process."""
    global _compiled
    if _compiled:
        return
    G = np.ones((4, 4))
    path = np.array([0, 1, 2, 3, 0], dtype=np.int64)
    holes = np.array([0, 1, 2], dtype=np.int64)
    near = np.array([[1, 2], [0, 2], [0, 1]], dtype=np.int64)
    gnodes, goff = np.array([1, 2, 3], dtype=np.int64), np.array([0, 1, 2, 3], dtype=np.int64)
    improve_path(G, path, 1)
    improve_path_near(G, path, holes, near, 1)
    layered(G, holes, gnodes, goff)
    one, rest = holes[:1], holes[1:]
    insert(G, one, gnodes[:1], rest, gnodes, goff)
    insert_near(G, one, gnodes[:1], rest, gnodes, goff, near)
    _compiled = True


_compiled = False
