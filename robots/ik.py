"""Closed-form inverse kinematics of the ABB six-axis arms (spherical wrist).

The wrist centre ``p_w = p_tool0 - d6 * z_tool0`` fixes joints 1-3: J1 points
the arm plane at the wrist centre (front) or away from it (back, J1 + pi); in
that plane the upper arm (a2) and the forearm (d4 with the a3 step) form a
triangle with two elbow solutions. The wrist orientation
``R_3_6 = Rz(q4) Ry(-q5) Rz(q6 + pi)`` (from the D-H table) gives two wrist
solutions (flip: q4 + pi, -q5, q6 + pi). That is up to 8 branches, numbered
``4 * back + 2 * elbow_down + wrist_flip``; every joint value 2*pi apart that
lies within the limits is returned too. Every solution is checked by forward
kinematics (position 1e-9 m, orientation 1e-9 rad).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import lru_cache
from itertools import product

import numpy as np
from numpy.typing import NDArray

from robots.dh import DHTable, fk_dh

Array = NDArray[np.float64]

TWO_PI = 2.0 * math.pi
#: solutions whose |sin q5| is below this are wrist-singular (a continuum of q4, q6)
WRIST_SINGULAR_TOL = 1e-7
#: a wrist centre closer than this to the J1 axis is shoulder-singular (m)
SHOULDER_SINGULAR_TOL_M = 1e-9
#: forward kinematics must reproduce the target to within these
POSITION_TOL_M = 1e-9
ORIENTATION_TOL = 1e-9


@dataclass(frozen=True)
class IKResult:
    """Solutions of one IK query.

    Attributes:
        solutions: (k, 6) joint vectors (rad): every branch, every value 2*pi apart in limits.
        branches: (k,) branch number 0..7 of each solution.
        reason: ``None`` when there are solutions, else why not ("out of reach", "wrist singular",
            "shoulder singular", "outside limits").
    """

    solutions: Array
    branches: NDArray[np.int64]
    reason: str | None = None
    n_branches: int = field(default=0)

    @property
    def ok(self) -> bool:
        """True when at least one solution exists."""
        return len(self.solutions) > 0


@dataclass(frozen=True)
class _Geometry:
    a1: float
    a2: float
    a3: float
    d1: float
    d4: float
    d6: float

    @classmethod
    def of(cls, table: DHTable) -> _Geometry:
        return _geometry_of(table)


@lru_cache(maxsize=64)
def _geometry_of(table: DHTable) -> _Geometry:
    a, d = table.a_m, table.d_m
    return _Geometry(a1=a[0], a2=a[1], a3=a[2], d1=d[0], d4=d[3], d6=d[5])


def _arm_solutions(g: _Geometry, p_w: Array) -> tuple[list[tuple[float, float, float, int]], str]:
    """Joint 1-3 solutions ``(q1, q2, q3, branch_base)`` for a wrist centre (m)."""
    px, py, pz = float(p_w[0]), float(p_w[1]), float(p_w[2])
    rho = math.hypot(px, py)
    if rho < SHOULDER_SINGULAR_TOL_M:
        return [], "shoulder singular"
    L2 = g.d4 * g.d4 + g.a3 * g.a3
    L = math.sqrt(L2)
    phi = math.atan2(g.d4, g.a3)
    out = []
    base_angle = math.atan2(py, px)
    for back in (0, 1):
        q1 = base_angle + math.pi * back
        r = (-rho if back else rho) - g.a1
        h = pz - g.d1
        k = (r * r + h * h - g.a2 * g.a2 - L2) / (2.0 * g.a2 * L)
        if abs(k) > 1.0:
            continue
        acos_k = math.acos(k)
        for elbow in (0, 1):
            q3 = (acos_k if elbow else -acos_k) - phi
            s3, c3 = math.sin(q3), math.cos(q3)
            ux = g.d4 * c3 + g.a3 * s3
            uz = g.a2 - g.d4 * s3 + g.a3 * c3
            q2 = math.atan2(r, h) - math.atan2(ux, uz)
            out.append((q1, q2, q3, 4 * back + 2 * elbow))
    return out, "out of reach"


def _wrist_solutions(
    q1: float, q23: float, R: list[list[float]]
) -> list[tuple[float, float, float, int]]:
    """Joint 4-6 solutions ``(q4, q5, q6, flip)``; empty when the wrist is singular.

    ``M = R_0_3^T R`` with ``R_0_3 = Rz(q1) Ry(q2 + q3) [[0,0,1],[0,-1,0],[1,0,0]]`` (the
    orientation of D-H frame 3) and ``R`` the target orientation, as nested lists. Only the five
    entries of ``M`` that the angles need are formed, in plain floats (this is the hot loop).
    """
    c1, s1, c23, s23 = math.cos(q1), math.sin(q1), math.cos(q23), math.sin(q23)
    x0, x1, x2 = c1 * s23, s1 * s23, c23  # column 0 of R_0_3
    z0, z1, z2 = c1 * c23, s1 * c23, -s23  # column 2 of R_0_3
    m02 = x0 * R[0][2] + x1 * R[1][2] + x2 * R[2][2]
    m12 = s1 * R[0][2] - c1 * R[1][2]  # column 1 of R_0_3 is (s1, -c1, 0)
    m22 = z0 * R[0][2] + z1 * R[1][2] + z2 * R[2][2]
    m20 = z0 * R[0][0] + z1 * R[1][0] + z2 * R[2][0]
    m21 = z0 * R[0][1] + z1 * R[1][1] + z2 * R[2][1]
    s5_abs = math.hypot(m02, m12)
    if s5_abs < WRIST_SINGULAR_TOL:
        return []
    q5 = math.atan2(s5_abs, m22)
    q4 = math.atan2(-m12, -m02)
    q6 = math.atan2(-m21, m20) - math.pi
    return [(q4, q5, q6, 0), (q4 + math.pi, -q5, q6 + math.pi, 1)]


def solve_ik(table: DHTable, T_base_tool0: Array, lower: Array, upper: Array) -> IKResult:
    """Every joint solution (rad) placing ``tool0`` at ``T_base_tool0`` within ``[lower, upper]``.

    The table must have the nominal ABB alpha and theta offsets (lengths may differ).
    """
    g = _geometry_of(table)
    R = T_base_tool0[:3, :3]
    p_w = T_base_tool0[:3, 3] - g.d6 * R[:, 2]
    arm, arm_reason = _arm_solutions(g, p_w)
    R_list = R.tolist()
    if not arm:
        return _empty(arm_reason, 0)
    raw: list[tuple[float, ...]] = []
    branches: list[int] = []
    for q1, q2, q3, branch in arm:
        for q4, q5, q6, flip in _wrist_solutions(q1, q2 + q3, R_list):
            raw.append((q1, q2, q3, q4, q5, q6))
            branches.append(branch + flip)
    if not raw:
        return _empty("wrist singular", 0)
    Q = np.array(raw)
    keep = _verified(table, Q, T_base_tool0)
    if not keep.any():
        return _empty("out of reach", len(raw))
    sols, branch_ids = expand_within_limits(Q[keep], np.array(branches)[keep], lower, upper)
    if not len(sols):
        return _empty("outside limits", len(raw))
    return IKResult(sols, branch_ids, None, len(raw))


def expand_within_limits(
    Q: Array, branches: NDArray[np.int64], lower: Array, upper: Array
) -> tuple[Array, NDArray[np.int64]]:
    """Every row of ``Q`` with each joint replaced by all its values 2*pi apart within limits.

    Rows with a joint that has no such value are dropped. Returns ``(solutions, branches)``.
    """
    grid, lo, hi = _shift_grid(
        tuple(np.asarray(lower, float).tolist()), tuple(np.asarray(upper, float).tolist())
    )
    cand = ((Q + math.pi) % TWO_PI - math.pi)[:, None, :] + grid
    inside = ((cand >= lo) & (cand <= hi)).all(axis=2)
    rows, cols = np.nonzero(inside)
    return np.clip(cand[rows, cols], lower, upper), branches[rows]


@lru_cache(maxsize=16)
def _shift_grid(lower: tuple[float, ...], upper: tuple[float, ...]) -> tuple[Array, Array, Array]:
    """Every combination of per-joint shifts ``2*pi*k`` taking a value in [-pi, pi) into limits.

    Also returns the limits widened by 1e-12 rad, so values on a limit are kept.
    """
    per_joint = []
    for lo, hi in zip(lower, upper, strict=True):
        ks = [k for k in range(-3, 4) if -math.pi + TWO_PI * k <= hi and math.pi + TWO_PI * k >= lo]
        per_joint.append([TWO_PI * k for k in ks])
    grid = np.array(list(product(*per_joint)), dtype=float).reshape(-1, len(lower))
    return grid, np.array(lower) - 1e-12, np.array(upper) + 1e-12


def _verified(table: DHTable, Q: Array, T_target: Array) -> NDArray[np.bool_]:
    T = fk_dh(table, Q)
    pos_err = np.linalg.norm(T[:, :3, 3] - T_target[:3, 3], axis=1)
    rot_err = np.abs(T[:, :3, :3] - T_target[:3, :3]).max(axis=(1, 2))
    return (pos_err < POSITION_TOL_M) & (rot_err < ORIENTATION_TOL)


def _empty(reason: str, n_branches: int) -> IKResult:
    return IKResult(np.zeros((0, 6)), np.zeros(0, dtype=np.int64), reason, n_branches)
