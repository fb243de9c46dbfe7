"""Imported by the local engine's fork server (:class:`planner.engines.LocalEngine`): loads
the search's compiled kernels (:mod:`planner.lns_compile`, from Numba's cache; compiled on
the very first use) once, while the parent prepares the shared part, so that every start
forked from the server has them in memory instead of loading them on its critical path."""

from planner.lns_compile import compile_kernels

compile_kernels()
