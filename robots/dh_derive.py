"""Classic D-H rows from the joint axis lines an arm's OPW parameters describe.

Frame 0 is ``base_link``, frame 6 is ``tool0``, ``theta_i = q_i + theta_offset_i`` with ``q`` in
URDF convention (see :mod:`robots.dh`). ``z_{i-1}`` is joint i's axis in the URDF's own
direction; ``x_i`` runs along the common normal from axis i to axis i+1 (from the foot on
axis i; for parallel axes from the previous origin); where the axes meet, ``x_i = ±z_{i-1} x
z_i`` with the sign closest to ``x_{i-1}``. For the ABB layout this gives exactly the table of
the ABB documentation (alpha -pi/2, 0, -pi/2, pi/2, -pi/2, 0; offsets 0, -pi/2, 0, 0, 0, pi).

A joint 1 turning about -z (KUKA's ``joint_a1``) gets ``joint_sign`` -1 (frame 0 must be
``base_link``, z up). A ``tool0`` whose z is not along joint 6's axis or whose origin is off it has
no D-H form with frame 6 = ``tool0`` and is refused with :class:`DHFormError`.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from robots.dh import DHTable
from robots.errors import DHFormError
from robots.opw import JointLine

Array = NDArray[np.float64]

TOL = 1e-9


def _snap_angle(a: float) -> float:
    for k in range(-4, 5):
        if abs(a - k * math.pi / 2) < 1e-12:
            a = k * math.pi / 2
    return math.pi if abs(a + math.pi) < 1e-12 else a


def _snap_length(v: float) -> float:
    return 0.0 if abs(v) < 1e-12 else float(round(v, 12))


def _angle_about(u: Array, v: Array, axis: Array) -> float:
    return math.atan2(float(np.cross(u, v) @ axis), float(u @ v))


def _common_normal(
    o: Array, z: Array, p: Array, w: Array, x_prev: Array
) -> tuple[Array, Array, float]:
    """Foot on line (o, z), unit x of the common normal toward line (p, w), and its length."""
    n = np.cross(z, w)
    if np.linalg.norm(n) < TOL:  # parallel: from o straight across
        foot = o
        across = (p - o) - ((p - o) @ w) * w
    else:
        nn = float(n @ n)
        w0 = o - p
        b, d, e = float(z @ w), float(z @ w0), float(w @ w0)
        foot = o + ((b * e - d) / nn) * z
        across = (p + ((e - b * d) / nn) * w) - foot
    length = float(np.linalg.norm(across))
    if length > TOL:
        return foot, across / length, length
    if np.linalg.norm(n) < TOL:
        return foot, x_prev, 0.0
    x = n / np.linalg.norm(n)
    return foot, (x if x @ x_prev >= 0 else -x), 0.0


def dh_from_lines(lines: list[JointLine], T_base_tool0_zero: Array) -> DHTable:
    """The D-H table (m, rad) of six joint axis lines at q = 0 and ``tool0`` at q = 0."""
    pts = [np.array(ln.point, float) for ln in lines]
    dirs = [np.array(ln.direction, float) / np.linalg.norm(ln.direction) for ln in lines]
    if np.linalg.norm(np.cross(dirs[0], [0.0, 0.0, 1.0])) > TOL or math.hypot(*pts[0][:2]) > TOL:
        raise DHFormError(
            lines[0].name,
            "the D-H form (frame 0 = base_link) needs joint 1 to turn about z through the origin",
        )
    # frame 0 is base_link: z0 = +z; a joint 1 about -z gets joint_sign -1
    sign1 = 1.0 if dirs[0][2] > 0 else -1.0
    o, x, z = np.zeros(3), np.array([1.0, 0.0, 0.0]), np.array([0.0, 0.0, 1.0])
    a, d, alpha, theta = [], [], [], []
    for i in range(5):
        foot, x_new, length = _common_normal(o, z, pts[i + 1], dirs[i + 1], x)
        z_new = dirs[i + 1]
        d.append(float((foot - o) @ z))
        theta.append(_angle_about(x, x_new, z))
        alpha.append(_angle_about(z, z_new, x_new))
        a.append(length)
        o, x, z = foot + length * x_new, x_new, z_new
    R_t, p_t = T_base_tool0_zero[:3, :3], T_base_tool0_zero[:3, 3]
    z6, x6 = R_t[:, 2], R_t[:, 0]
    off_axis = float(np.linalg.norm(np.cross(p_t - o, z)))
    if np.linalg.norm(np.cross(z6, z)) > TOL or off_axis > TOL:
        raise DHFormError(
            lines[5].name,
            "the D-H form (frame 6 = tool0) needs tool0's z along joint 6's axis, its origin on it",
        )
    d.append(float((p_t - o) @ z))
    theta.append(_angle_about(x, x6, z))
    alpha.append(_angle_about(z, z6, x6))
    a.append(0.0)
    return DHTable(
        a_m=tuple(_snap_length(v) for v in a),
        d_m=tuple(_snap_length(v) for v in d),
        alpha_rad=tuple(_snap_angle(v) for v in alpha),
        theta_offset_rad=tuple(_snap_angle(v) for v in theta),
        joint_sign=(sign1, 1.0, 1.0, 1.0, 1.0, 1.0),
    )
