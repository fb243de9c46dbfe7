"""The sequencer's cost matrix, built by this process and the helper process together.

:meth:`planner.costs.CostTable.matrix64` of 4000 nodes (250 holes) writes 128 MB: ~0.8 s of
CPU in the main process while the helper (:mod:`planner.helper`) waits. Here the matrix
lives in an anonymous shared memory file (``memfd_create``); the helper opens it through
``/proc/<pid>/fd`` and fills the entries whose smaller index is in the second share of the
row blocks while this process fills the first share (shares of equal work: the upper
triangle's blocks). Each entry is computed by the same arithmetic as in one process, so the
matrix is the same, bit for bit, with or without the helper; where the helper cannot help
(no ``memfd_create``, a helper that died or could not open the file) this process fills
the rest itself.
"""

from __future__ import annotations

import logging
import mmap
import os

import numpy as np
from numpy.typing import NDArray

from planner.costs import SYMMETRIC_BLOCK, CostTable
from planner.helper import Helper

log = logging.getLogger(__name__)

#: below this many nodes the matrix is built here alone (the hand-over costs ~10 ms)
SHARED_MIN_NODES = 1024

#: in the helper: the last matrix it filled (still mapped: the same memory as this
#: process's), for later shares of work on it (:func:`held_matrix`)
_HELD: dict[str, NDArray[np.float64]] = {}


def held_matrix() -> NDArray[np.float64] | None:
    """In the helper: the matrix its last :func:`fill_rows` filled (None: none)."""
    return _HELD.get("G")


def split_row(n: int) -> int:
    """First row (a multiple of ``SYMMETRIC_BLOCK``) of the second share of an ``n``-node
    symmetric matrix: the row blocks before it hold about half of the upper triangle."""
    starts = list(range(0, n, SYMMETRIC_BLOCK))
    sizes = [min(i0 + SYMMETRIC_BLOCK, n) - i0 for i0 in starts]
    work = [(n - i0) * b - b * (b - 1) // 2 for i0, b in zip(starts, sizes, strict=True)]
    half, done = sum(work) / 2.0, 0
    for i0, w in zip(starts, work, strict=True):
        if done + w / 2.0 > half:
            return i0
        done += w
    return n


def _shared_matrix(n: int) -> tuple[int, NDArray[np.float64]] | None:
    """A zeroed (n, n) float64 array in a new memory file, and the file's descriptor."""
    size = n * n * 8
    try:
        fd = os.memfd_create("holecell-costs", 0)
    except (AttributeError, OSError):
        return None
    try:
        os.ftruncate(fd, size)
        buf = mmap.mmap(fd, size)
    except OSError:
        os.close(fd)
        return None
    return fd, np.frombuffer(buf, dtype=np.float64).reshape(n, n)


def fill_rows(pid: int, fd: int, rows: NDArray[np.float64], table: CostTable, r0: int) -> bool:
    """In the helper: fill the rows from ``r0`` of process ``pid``'s memory file ``fd``
    (:meth:`CostTable.symmetric_rows`); False when the file cannot be opened."""
    n = rows.shape[0]
    try:
        with open(f"/proc/{pid}/fd/{fd}", "r+b") as f:
            buf = mmap.mmap(f.fileno(), n * n * 8)
    except OSError as exc:
        log.info("the helper cannot open the cost matrix (%s)", exc)
        return False
    out = np.frombuffer(buf, dtype=np.float64).reshape(n, n)
    _HELD.pop("G", None)
    table.symmetric_rows(rows, out, r0, n)
    _HELD["G"] = out  # the mapping lives as long as the array
    return True


def symmetric_costs(
    table: CostTable, q: NDArray[np.float64], helper: Helper | None = None
) -> tuple[NDArray[np.float64], bool]:
    """``table.matrix64(q)``, the same values, half of it made by ``helper`` where given;
    and whether the helper holds it (:func:`held_matrix`: it sees this process's later
    writes to it, the same memory)."""
    rows = np.atleast_2d(np.asarray(q, dtype=float))
    n = rows.shape[0]
    if helper is None or n < SHARED_MIN_NODES:
        return table.matrix64(rows), False
    made = _shared_matrix(n)
    if made is None:
        return table.matrix64(rows), False
    fd, out = made
    held = False
    try:
        r0 = split_row(n)
        theirs = helper.submit(fill_rows, os.getpid(), fd, rows, table, r0)
        table.symmetric_rows(rows, out, 0, r0)
        held = bool(Helper.result(theirs, lambda: False))
        if not held:
            table.symmetric_rows(rows, out, r0, n)
    finally:
        os.close(fd)  # the mapping stays while ``out`` lives
    return out, held
