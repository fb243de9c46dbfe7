"""Samples of straight joint motions at a resolution, for many motions at once (numpy).

A motion from ``a`` to ``b`` is sampled at ``a + t (b - a)``, ``t = k / n`` as
``np.linspace(0, 1, n + 1)``, with ``n`` the smallest count found by the rule of
:meth:`planner.paths.MotionChecker.samples`: no joint moves more than the joint step,
and the TCP no more than the TCP step, between two samples (``n`` grown by the worst TCP
step, at most 8 times). The functions here give the same counts and the same samples,
bit for bit, for a whole batch of motions without a Python loop per motion.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from planner.protocols import ArmLike


def tcp_positions(arm: ArmLike, Q: NDArray[np.float64]) -> NDArray[np.float64]:
    """TCP positions (N, 3) m of configurations ``Q`` (N, dof): the arm's fast point chain
    (``robots.Arm.tcp_positions``) where it has one, else its batched ``fk_dh``."""
    fast = getattr(arm, "tcp_positions", None)
    return fast(Q) if fast is not None else arm.fk_dh(Q, "tcp")[:, :3, 3]


def linspaces(n: NDArray[np.int64]) -> NDArray[np.float64]:
    """``np.linspace(0, 1, m + 1)`` for each ``m`` in ``n``, concatenated (the same values:
    ``k * (1 / m)``, the last exactly 1)."""
    reps = n + 1
    first = np.concatenate([[0], np.cumsum(reps)[:-1]])
    k = np.arange(int(reps.sum())) - np.repeat(first, reps)
    t = k * np.repeat(1.0 / n, reps)
    t[first + n] = 1.0
    return t


def motion_counts(
    arm: ArmLike,
    joint_step: float,
    tcp_step: float,
    A: NDArray[np.float64],
    B: NDArray[np.float64],
) -> NDArray[np.int64]:
    """Steps per motion ``A[i] → B[i]`` (rad): joint step (rad) and TCP step (m) rule."""
    n = np.maximum(np.ceil(np.abs(B - A).max(axis=1) / joint_step), 1).astype(np.int64)
    todo = np.arange(len(A))
    for _ in range(8):
        if not len(todo):
            break
        reps = n[todo] + 1
        t = linspaces(n[todo])[:, None]
        idx = np.repeat(todo, reps)
        Q = A[idx] + t * (B[idx] - A[idx])
        tcp = tcp_positions(arm, Q)
        step = np.linalg.norm(np.diff(tcp, axis=0), axis=1)
        step[np.cumsum(reps)[:-1] - 1] = 0.0  # no step across two motions
        worst = np.maximum.reduceat(
            np.append(step, 0.0), np.concatenate([[0], np.cumsum(reps)[:-1]])
        )
        bad = worst > tcp_step
        n[todo[bad]] = np.ceil(n[todo[bad]] * worst[bad] / tcp_step * 1.05).astype(np.int64)
        todo = todo[bad]
    return n


def interior_samples(
    A: NDArray[np.float64],
    B: NDArray[np.float64],
    n: NDArray[np.int64],
    order: object,
) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """Every motion's ``n[i] - 1`` interior samples in one array, each motion's in the order
    ``order(n[i])`` (indices 1..n-1); and the bounds: motion i is rows ``bounds[i]:bounds[i+1]``.
    """
    sizes = n - 1
    parts = [order(int(m)) for m in n]  # type: ignore[operator]
    k = np.concatenate(parts) if parts else np.zeros(0, np.int64)
    idx = np.repeat(np.arange(len(A)), sizes)
    t = (k * np.repeat(1.0 / n, sizes))[:, None]
    Q = A[idx] + t * (B[idx] - A[idx])
    return Q, np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64)
