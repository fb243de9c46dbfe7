"""Closed-form inverse kinematics of ortho-parallel arms with a spherical wrist (OPW family).

Works on the canonical OPW chain of :mod:`robots.opw` (parameters a1, a2, b, c1..c4, joint
signs and offsets, derived from the URDF). The wrist centre ``p_c = p_E - c4 * z_E`` fixes
joints 1-3: J1 turns the arm plane to the wrist centre (front) or away from it (back); in that
plane the upper arm (c2) and the forearm (a2, c3) form a triangle with two elbow solutions.
The wrist orientation ``Rz(q4) Ry(q5) Rz(q6)`` gives two wrist solutions (flip: q4 + pi, -q5,
q6 + pi). That is up to 8 branches, numbered ``4 * back + 2 * elbow + wrist_flip``; every
joint value 2*pi apart that lies within the limits is returned too. Every solution is checked
by forward kinematics (position 1e-9 m, orientation 1e-9 rad).

:func:`solve_ik` takes a D-H table (:mod:`robots.dh`) and solves it through the same OPW
solver; :func:`solve_opw` takes OPW parameters of any arm of the family.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from functools import lru_cache
from itertools import product

import numpy as np
from numpy.typing import NDArray

from robots.dh import DHTable, fk_dh, fk_dh_frames
from robots.dh_derive import dh_from_lines
from robots.opw import JointLine, OpwParameters, derive_opw, fk_opw, joint_lines_of

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
    """The numbers the hot loop needs, as plain floats and ready arrays."""

    a1: float
    a2: float
    b: float
    c1: float
    c2: float
    c3: float
    c4: float
    kappa: float
    psi: float
    sign: Array
    offset: Array
    T_tool0_e: Array | None  # None when tool0 is the canonical end frame E
    canonical_table: DHTable  # D-H rows of the canonical chain (base to E), for the FK check


@lru_cache(maxsize=64)
def _geometry_of(params: OpwParameters) -> _Geometry:
    T_E_tool0 = params.tool()
    identity = bool(np.abs(T_E_tool0 - np.eye(4)).max() < 1e-15)
    return _Geometry(
        a1=params.a1,
        a2=params.a2,
        b=params.b,
        c1=params.c1,
        c2=params.c2,
        c3=params.c3,
        c4=params.c4,
        kappa=math.hypot(params.a2, params.c3),
        psi=math.atan2(params.a2, params.c3),
        sign=np.array(params.sign, float),
        offset=np.array(params.offset_rad, float),
        T_tool0_e=None if identity else np.asarray(np.linalg.inv(T_E_tool0), dtype=np.float64),
        canonical_table=_canonical_table(params),
    )


def _canonical_table(params: OpwParameters) -> DHTable:
    """D-H rows of the canonical chain (signs +1, offsets 0, tool0 = E): a fast exact FK."""
    canon = replace(
        params,
        sign=(1.0,) * 6,
        offset_rad=(0.0,) * 6,
        T_E_tool0=tuple(tuple(r) for r in np.eye(4).tolist()),
    )
    return dh_from_lines(joint_lines_of(canon), fk_opw(canon, np.zeros(6)))


def opw_of_table(table: DHTable) -> OpwParameters:
    """OPW parameters of a D-H table (its joint axes at q = 0); NotOpwError if it has none."""
    return _opw_of_table(table)


@lru_cache(maxsize=64)
def _opw_of_table(table: DHTable) -> OpwParameters:
    frames = fk_dh_frames(table, np.zeros(6))
    lines = [
        JointLine(
            f"joint_{i + 1}",
            tuple(frames[i, :3, 3].tolist()),
            tuple((frames[i, :3, 2] * table.joint_sign[i]).tolist()),
        )
        for i in range(6)
    ]
    return derive_opw(lines, frames[6])


def _arm_solutions(
    g: _Geometry, p_c: list[float]
) -> tuple[list[tuple[float, float, float, int]], str]:
    """Canonical joint 1-3 solutions ``(q1, q2, q3, branch_base)`` for a wrist centre (m)."""
    cx, cy, cz = p_c
    rho2 = cx * cx + cy * cy - g.b * g.b
    if math.hypot(cx, cy) < SHOULDER_SINGULAR_TOL_M or rho2 < SHOULDER_SINGULAR_TOL_M**2:
        return [], "shoulder singular" if g.b == 0.0 else "out of reach"
    x = math.sqrt(rho2)
    base_angle = math.atan2(cy, cx)
    h = cz - g.c1
    out = []
    for back in (0, 1):
        xs = -x if back else x
        q1 = base_angle - math.atan2(g.b, xs)
        r = xs - g.a1
        k = (r * r + h * h - g.c2 * g.c2 - g.kappa * g.kappa) / (2.0 * g.c2 * g.kappa)
        if abs(k) > 1.0:
            continue
        acos_k = math.acos(k)
        reach = math.atan2(r, h)
        for elbow in (0, 1):
            beta = -acos_k if elbow else acos_k
            q2 = reach - math.atan2(g.kappa * math.sin(beta), g.c2 + g.kappa * math.cos(beta))
            out.append((q1, q2, beta - g.psi, 4 * back + 2 * elbow))
    return out, "out of reach"


def _wrist(q1: float, q23: float, R: list[list[float]]) -> list[tuple[float, float, float, int]]:
    """Canonical joint 4-6 solutions ``(q4, q5, q6, flip)``; empty when the wrist is singular.

    ``M = R_0c^T R`` with ``R_0c = Rz(q1) Ry(q23)`` and ``R`` the end frame's orientation, as
    nested lists; only the five entries of ``M`` the ZYZ angles need are formed (the hot loop).
    """
    c1, s1, c23, s23 = math.cos(q1), math.sin(q1), math.cos(q23), math.sin(q23)
    x0, x1, x2 = c1 * c23, s1 * c23, -s23  # column 0 of R_0c
    z0, z1, z2 = c1 * s23, s1 * s23, c23  # column 2 of R_0c
    m02 = x0 * R[0][2] + x1 * R[1][2] + x2 * R[2][2]
    m12 = -s1 * R[0][2] + c1 * R[1][2]  # column 1 of R_0c is (-s1, c1, 0)
    m22 = z0 * R[0][2] + z1 * R[1][2] + z2 * R[2][2]
    m20 = z0 * R[0][0] + z1 * R[1][0] + z2 * R[2][0]
    m21 = z0 * R[0][1] + z1 * R[1][1] + z2 * R[2][1]
    s5_abs = math.hypot(m02, m12)
    if s5_abs < WRIST_SINGULAR_TOL:
        return []
    q5 = math.atan2(s5_abs, m22)
    q4 = math.atan2(m12, m02)
    q6 = math.atan2(m21, -m20)
    return [(q4, q5, q6, 0), (q4 + math.pi, -q5, q6 + math.pi, 1)]


def _wrist_solutions(
    q1: float, q23: float, R: list[list[float]]
) -> list[tuple[float, float, float, int]]:
    """Joint 4-6 solutions of an ABB arm for its J1 and J2 + J3 (URDF values) and tool0's ``R``."""
    return _wrist(q1, q23 + math.pi / 2, R)


def solve_opw(params: OpwParameters, T_base_tool0: Array, lower: Array, upper: Array) -> IKResult:
    """Every joint solution (URDF rad) placing ``tool0`` at ``T_base_tool0`` within limits."""
    return solve_opw_many(params, np.asarray(T_base_tool0, float)[None], lower, upper)[0]


def solve_opw_many(
    params: OpwParameters, T_base_tool0: Array, lower: Array, upper: Array
) -> list[IKResult]:
    """:func:`solve_opw` of each pose of ``T_base_tool0`` (P, 4, 4), the same results as one
    pose at a time, bit for bit: the closed form pose by pose, the FK check and the 2*pi
    shifts of all poses' raw solutions in one array call each (a hole's viewpoints: a fifth
    of the time)."""
    g = _geometry_of(params)
    raw: list[tuple[float, ...]] = []
    branches: list[int] = []
    owner: list[int] = []
    targets, counts, early = [], [], []
    for i, T in enumerate(np.asarray(T_base_tool0, float)):
        T_E = T if g.T_tool0_e is None else T @ g.T_tool0_e
        targets.append(T_E)
        R = T_E[:3, :3].tolist()
        p = T_E[:3, 3].tolist()
        arm, arm_reason = _arm_solutions(g, [p[k] - g.c4 * R[k][2] for k in range(3)])
        n0 = len(raw)
        for q1, q2, q3, branch in arm:
            for q4, q5, q6, flip in _wrist(q1, q2 + q3, R):
                raw.append((q1, q2, q3, q4, q5, q6))
                branches.append(branch + flip)
        counts.append(len(raw) - n0)
        early.append(arm_reason if not arm else "wrist singular" if len(raw) == n0 else None)
        owner += [i] * (len(raw) - n0)
    Qc, rows_of = np.array(raw, dtype=float).reshape(-1, 6), np.array(owner, dtype=np.int64)
    keep = _verified(fk_dh(g.canonical_table, Qc), np.array(targets).reshape(-1, 4, 4)[rows_of])
    sols, src = _expand(((Qc[keep] - g.offset) * g.sign), lower, upper)
    bids = np.array(branches, dtype=np.int64)[keep][src]
    pose_of = rows_of[keep][src]
    verified = np.bincount(rows_of[keep], minlength=len(targets))
    cut = np.searchsorted(pose_of, np.arange(len(targets) + 1))
    out = []
    for i, reason in enumerate(early):
        a, b = cut[i], cut[i + 1]
        if reason is not None:
            out.append(_empty(reason, 0))
        elif not verified[i]:
            out.append(_empty("out of reach", counts[i]))
        elif a == b:
            out.append(_empty("outside limits", counts[i]))
        else:
            out.append(IKResult(sols[a:b], bids[a:b], None, counts[i]))
    return out


def solve_ik(table: DHTable, T_base_tool0: Array, lower: Array, upper: Array) -> IKResult:
    """Every joint solution (rad) placing ``tool0`` at ``T_base_tool0`` within ``[lower, upper]``.

    Any table of an OPW chain (the ABB layout, a Fanuc's, a KUKA's with ``joint_sign``): its
    OPW parameters are read from its joint axes at q = 0; solutions are also checked against the
    table's own forward kinematics.
    """
    result = solve_opw(opw_of_table(table), T_base_tool0, lower, upper)
    if result.ok:
        ok = _verified(fk_dh(table, result.solutions), T_base_tool0)
        return IKResult(result.solutions[ok], result.branches[ok], result.reason, result.n_branches)
    return result


def _expand(Q: Array, lower: Array, upper: Array) -> tuple[Array, NDArray[np.int64]]:
    """Every row of ``Q`` with each joint replaced by all its values 2*pi apart within limits
    (rows with a joint that has no such value are dropped), and each solution's row of ``Q``."""
    grid, lo, hi = _shift_grid(
        tuple(np.asarray(lower, float).tolist()), tuple(np.asarray(upper, float).tolist())
    )
    cand = ((Q + math.pi) % TWO_PI - math.pi)[:, None, :] + grid
    inside = ((cand >= lo) & (cand <= hi)).all(axis=2)
    rows, cols = np.nonzero(inside)
    return np.clip(cand[rows, cols], lower, upper), rows


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


def _verified(T: Array, T_target: Array) -> NDArray[np.bool_]:
    """Rows of ``T`` (k, 4, 4) within the tolerances of ``T_target`` (4, 4), or of its row
    (k, 4, 4)."""
    pos_err = np.linalg.norm(T[:, :3, 3] - T_target[..., :3, 3], axis=1)
    rot_err = np.abs(T[:, :3, :3] - T_target[..., :3, :3]).max(axis=(1, 2))
    return (pos_err < POSITION_TOL_M) & (rot_err < ORIENTATION_TOL)


def _empty(reason: str, n_branches: int) -> IKResult:
    return IKResult(np.zeros((0, 6)), np.zeros(0, dtype=np.int64), reason, n_branches)
