"""OPW parameters of an ortho-parallel 6R arm with a spherical wrist, derived from its joint axes.

The OPW family (Brandstötter, Angerer, Hofbaur 2014, "An analytical solution of the inverse
kinematics problem of industrial serial manipulators with an ortho-parallel basis and a
spherical wrist") covers ABB, KUKA KR, Fanuc, Stäubli and Yaskawa mid-size arms. Its canonical
chain, in an *arm frame* ``A`` that is ``base_link`` turned about z (m, rad)::

    p_wrist = Rz(q1) [a1 + c2 sin q2 + a2 cos q23 + c3 sin q23,  b,
                      c1 + c2 cos q2 - a2 sin q23 + c3 cos q23]          (q23 = q2 + q3)
    R_E     = Rz(q1) Ry(q23) Rz(q4) Ry(q5) Rz(q6),   p_E = p_wrist + c4 R_E z

with canonical joint values ``q_opw = sign * q + offset`` (``q`` in URDF convention). The URDF's
``tool0`` is ``T_E_tool0`` from ``E``. :func:`derive_opw` reads the joint axis lines at q = 0
(a serial chain is fully fixed by them and the tool pose, product of exponentials) and refuses a
chain that is not OPW, naming the joint and the property that fails.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robots.errors import NotOpwError

Array = NDArray[np.float64]

#: a geometric property holds when it is off by less than this (m, or unit-vector components)
GEOMETRY_TOL = 1e-9


@dataclass(frozen=True)
class JointLine:
    """A joint's axis at q = 0 in ``base_link``: a point on it (m) and its unit direction."""

    name: str
    point: tuple[float, float, float]
    direction: tuple[float, float, float]


@dataclass(frozen=True)
class OpwParameters:
    """The OPW parameters (m, rad) with the joint signs/offsets and the fixed tool transform.

    Attributes:
        a1, a2, b, c1, c2, c3, c4: lengths as in Brandstötter et al. (m); ``a2`` is the forearm
            step along the canonical x, negative when the forearm sits above J3 (ABB).
        sign: +1/-1 per joint, canonical rotation = sign * URDF rotation.
        offset_rad: canonical joint value at URDF q = 0, per joint.
        T_E_tool0: the URDF's ``tool0`` in the canonical end frame ``E`` (4x4).
        joint_names: the URDF's six joint names in chain order.
    """

    a1: float
    a2: float
    b: float
    c1: float
    c2: float
    c3: float
    c4: float
    sign: tuple[float, ...]
    offset_rad: tuple[float, ...]
    T_E_tool0: tuple[tuple[float, ...], ...]
    joint_names: tuple[str, ...]

    def tool(self) -> Array:
        """``T_E_tool0`` as a 4x4 array."""
        return np.array(self.T_E_tool0, dtype=float)

    def lengths(self) -> dict[str, float]:
        """The seven lengths by name (m)."""
        return {k: getattr(self, k) for k in ("a1", "a2", "b", "c1", "c2", "c3", "c4")}


def _rz(t: float) -> Array:
    c, s = math.cos(t), math.sin(t)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _ry(t: float) -> Array:
    c, s = math.cos(t), math.sin(t)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def _sign(x: float) -> float:
    return -1.0 if x < 0 else 1.0


def _line_distance(p1: Array, d1: Array, p2: Array, d2: Array) -> tuple[float, Array]:
    """Distance (m) between two non-parallel lines and the midpoint of their common normal."""
    n = np.cross(d1, d2)
    nn = float(n @ n)
    w0 = p1 - p2
    b = float(d1 @ d2)
    d, e = float(d1 @ w0), float(d2 @ w0)
    t = (b * e - d) / nn
    s = (e - b * d) / nn
    c1, c2 = p1 + t * d1, p2 + s * d2
    return float(np.linalg.norm(c1 - c2)), 0.5 * (c1 + c2)


def derive_opw(lines: list[JointLine], T_base_tool0: Array) -> OpwParameters:
    """OPW parameters from six joint axis lines at q = 0 and ``T_base_tool0`` at q = 0.

    Raises :class:`NotOpwError` naming the joint and the property that fails.
    """
    if len(lines) != 6:
        raise NotOpwError("(chain)", f"has {len(lines)} moving joints, OPW needs 6 revolute joints")
    n = [ln.name for ln in lines]
    p = [np.array(ln.point, float) for ln in lines]
    w_ = [np.array(ln.direction, float) / np.linalg.norm(ln.direction) for ln in lines]
    tol = GEOMETRY_TOL
    z = np.array([0.0, 0.0, 1.0])
    # joint 1: the base z axis through base_link's origin
    if np.linalg.norm(np.cross(w_[0], z)) > tol:
        raise NotOpwError(n[0], f"axis {np.round(w_[0], 6).tolist()} is not the base z axis")
    if math.hypot(p[0][0], p[0][1]) > tol:
        off = math.hypot(p[0][0], p[0][1])
        raise NotOpwError(n[0], f"axis does not pass through base_link's origin ({off:.6g} m off)")
    s1 = _sign(w_[0][2])
    # joint 2: perpendicular to joint 1; its horizontal offset fixes the arm frame's x
    if abs(w_[1][2]) > tol:
        raise NotOpwError(n[1], f"axis is not perpendicular to {n[0]}'s axis")
    w2 = np.array([w_[1][0], w_[1][1], 0.0]) / math.hypot(w_[1][0], w_[1][1])
    x_arm = _arm_x(w2, p)
    y_arm = np.cross(z, x_arm)
    theta1 = math.atan2(x_arm[1], x_arm[0])
    R_A = np.column_stack((x_arm, y_arm, z))
    pa = [R_A.T @ v for v in p]
    wa = [R_A.T @ v for v in w_]
    s2 = _sign(wa[1][1])
    a1, c1 = float(pa[1][0]), float(pa[1][2])
    # joint 3 parallel to joint 2
    if np.linalg.norm(np.cross(wa[2], wa[1])) > tol:
        raise NotOpwError(n[2], f"axis is not parallel to {n[1]}'s axis")
    s3 = _sign(wa[2][1])
    ux, uz = float(pa[2][0]) - a1, float(pa[2][2]) - c1
    c2 = math.hypot(ux, uz)
    if c2 < tol:
        raise NotOpwError(n[2], f"axis coincides with {n[1]}'s axis (no upper arm)")
    theta2 = math.atan2(ux, uz)
    # spherical wrist: joints 4, 5, 6 meet in one point
    if abs(wa[3][1]) > tol:
        raise NotOpwError(n[3], f"axis is not perpendicular to {n[2]}'s axis")
    if abs(float(wa[4] @ wa[3])) > tol:
        raise NotOpwError(n[4], f"axis is not perpendicular to {n[3]}'s axis")
    gap45, wc = _line_distance(pa[3], wa[3], pa[4], wa[4])
    if gap45 > tol:
        raise NotOpwError(n[4], f"axis misses {n[3]}'s axis by {gap45:.6g} m (wrist not spherical)")
    if abs(float(wa[5] @ wa[4])) > tol:
        raise NotOpwError(n[5], f"axis is not perpendicular to {n[4]}'s axis")
    miss6 = float(np.linalg.norm(np.cross(wc - pa[5], wa[5])))
    if miss6 > tol:
        raise NotOpwError(n[5], f"axis misses the wrist centre by {miss6:.6g} m (not spherical)")
    dx, dz = float(wc[0]) - float(pa[2][0]), float(wc[2]) - float(pa[2][2])
    f = np.array([wa[3][0], 0.0, wa[3][2]])
    f /= np.linalg.norm(f)
    if f[0] * dx + f[2] * dz < 0:
        f = -f
    s4 = _sign(float(wa[3] @ f))
    phi = math.atan2(f[0], f[2])
    theta3 = phi - theta2
    a2 = dx * math.cos(phi) - dz * math.sin(phi)
    c3 = dx * math.sin(phi) + dz * math.cos(phi)
    b = float(wc[1])
    F0 = _ry(phi)
    u = F0.T @ wa[4]
    s5 = _sign(float(u[1]))
    theta4 = math.atan2(-s5 * u[0], s5 * u[1])
    F1 = F0 @ _rz(theta4)
    v = F1.T @ wa[5]
    s6 = _sign(float(v[2]))
    theta5 = math.atan2(s6 * v[0], s6 * v[2])
    R_AE = F1 @ _ry(theta5)
    T_A_tool0 = np.eye(4)
    T_A_tool0[:3, :3] = R_A.T @ T_base_tool0[:3, :3]
    T_A_tool0[:3, 3] = R_A.T @ T_base_tool0[:3, 3]
    c4 = float((T_A_tool0[:3, 3] - wc) @ R_AE[:, 2])
    T_A_E = np.eye(4)
    T_A_E[:3, :3] = R_AE
    T_A_E[:3, 3] = wc + c4 * R_AE[:, 2]
    T_E_tool0 = np.linalg.inv(T_A_E) @ T_A_tool0
    return OpwParameters(
        a1=a1,
        a2=a2,
        b=b,
        c1=c1,
        c2=c2,
        c3=c3,
        c4=c4,
        sign=(s1, s2, s3, s4, s5, s6),
        offset_rad=(theta1, theta2, theta3, theta4, theta5, 0.0),
        T_E_tool0=tuple(tuple(float(x) for x in row) for row in T_E_tool0),
        joint_names=tuple(n),
    )


def _arm_x(w2: Array, p: list[Array]) -> Array:
    """The arm frame's x: from the J1 axis toward the J2 axis (or the wrist when they meet)."""
    for point in (p[1], p[3], p[4]):
        h = np.array([point[0], point[1], 0.0])
        h -= (h @ w2) * w2
        if np.linalg.norm(h) > GEOMETRY_TOL:
            return h / np.linalg.norm(h)
    return np.cross(w2, np.array([0.0, 0.0, 1.0]))


def canonical_q(params: OpwParameters, q: ArrayLike) -> Array:
    """Canonical OPW joint values (rad) from URDF joint values ``q`` (..., 6)."""
    return np.asarray(q, float) * np.array(params.sign) + np.array(params.offset_rad)


def fk_opw(params: OpwParameters, q: ArrayLike) -> Array:
    """``T_base_tool0`` (..., 4, 4) from URDF joint values ``q`` (..., 6) rad."""
    qc = canonical_q(params, q)
    q1, q2, q4, q5, q6 = qc[..., 0], qc[..., 1], qc[..., 3], qc[..., 4], qc[..., 5]
    q23 = q2 + qc[..., 2]
    c1, s1 = np.cos(q1), np.sin(q1)
    s23, c23 = np.sin(q23), np.cos(q23)
    px = params.a1 + params.c2 * np.sin(q2) + params.a2 * c23 + params.c3 * s23
    pz = params.c1 + params.c2 * np.cos(q2) - params.a2 * s23 + params.c3 * c23
    shape = qc.shape[:-1]
    R0c = np.zeros((*shape, 3, 3))
    R0c[..., 0, 0], R0c[..., 0, 1], R0c[..., 0, 2] = c1 * c23, -s1, c1 * s23
    R0c[..., 1, 0], R0c[..., 1, 1], R0c[..., 1, 2] = s1 * c23, c1, s1 * s23
    R0c[..., 2, 0], R0c[..., 2, 2] = -s23, c23
    Rce = _zyz(q4, q5, q6)
    T = np.zeros((*shape, 4, 4))
    T[..., :3, :3] = R0c @ Rce
    T[..., 0, 3] = c1 * px - s1 * params.b
    T[..., 1, 3] = s1 * px + c1 * params.b
    T[..., 2, 3] = pz
    T[..., :3, 3] += params.c4 * T[..., :3, 2]
    T[..., 3, 3] = 1.0
    return T @ params.tool()


def _zyz(a: Array, b: Array, c: Array) -> Array:
    ca, sa, cb, sb, cc, sc = np.cos(a), np.sin(a), np.cos(b), np.sin(b), np.cos(c), np.sin(c)
    R = np.empty((*np.shape(a), 3, 3))
    R[..., 0, 0] = ca * cb * cc - sa * sc
    R[..., 0, 1] = -ca * cb * sc - sa * cc
    R[..., 0, 2] = ca * sb
    R[..., 1, 0] = sa * cb * cc + ca * sc
    R[..., 1, 1] = -sa * cb * sc + ca * cc
    R[..., 1, 2] = sa * sb
    R[..., 2, 0] = -sb * cc
    R[..., 2, 1] = sb * sc
    R[..., 2, 2] = cb
    return R


def joint_lines_of(params: OpwParameters) -> list[JointLine]:
    """The six joint axis lines at URDF q = 0 (base_link, m) that these parameters describe."""
    th = params.offset_rad
    R_A = _rz(th[0])
    q23 = th[1] + th[2]
    j2 = R_A @ np.array([params.a1, 0.0, params.c1])
    j3 = j2 + R_A @ (_ry(th[1]) @ np.array([0.0, 0.0, params.c2]))
    R0c = R_A @ _ry(q23)
    wc = j3 + R0c @ np.array([params.a2, 0.0, params.c3]) + R_A @ np.array([0.0, params.b, 0.0])
    R1 = R0c @ _rz(th[3])
    R2 = R1 @ _ry(th[4])
    y_A = R_A[:, 1]
    dirs = [
        np.array([0.0, 0.0, 1.0]),
        y_A,
        y_A,
        R0c[:, 2],
        R1[:, 1],
        R2[:, 2],
    ]
    points = [np.zeros(3), j2, j3, wc, wc, wc]
    return [
        JointLine(name, tuple(pt.tolist()), tuple((s * d).tolist()))
        for name, pt, d, s in zip(params.joint_names, points, dirs, params.sign, strict=True)
    ]
