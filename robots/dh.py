"""Classic (distal) Denavit-Hartenberg tables: the ABB models' and any OPW arm's.

Link i maps frame i-1 to frame i by ``Rz(theta_i) Tz(d_i) Tx(a_i) Rx(alpha_i)``
with ``theta_i = q_i + theta_offset_i``. Frame 0 is ``base_link``; frame 6 is
``tool0``. Lengths in metres, angles in radians. For the ABB chains:

    theta offset = [0, -pi/2, 0, 0, 0, pi]
    alpha        = [-pi/2, 0, -pi/2, pi/2, -pi/2, 0]
    d            = [d1, 0, 0, d4, 0, d6]
    a            = [a1, a2, a3, 0, 0, 0]

The thermal model (:mod:`robots.thermal`) scales ``a`` and ``d`` and adds
offsets to ``theta``; so forward kinematics takes the table as an argument.
Tables are derived from the URDF (:mod:`robots.dh_derive`), never kept by hand; the
built-in models' tables are :func:`robots.dh_models.dh_table`.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, replace
from functools import lru_cache

import numpy as np
from numpy.typing import ArrayLike, NDArray

Array = NDArray[np.float64]


@dataclass(frozen=True)
class DHTable:
    """A six-link classic D-H table (m, rad).

    ``joint_sign`` (+1/-1 per joint, default all +1) turns URDF joint values into D-H ones,
    ``theta_i = joint_sign_i * q_i + theta_offset_i``: -1 where the joint turns about -z_{i-1}
    (joint 1 of a KUKA arm turns about -z of ``base_link``, which frame 0 must be).
    """

    a_m: tuple[float, ...]
    d_m: tuple[float, ...]
    alpha_rad: tuple[float, ...]
    theta_offset_rad: tuple[float, ...]
    joint_sign: tuple[float, ...] = (1.0,) * 6

    def joint_values(self, q: ArrayLike) -> Array:
        """D-H joint variables ``joint_sign * q`` (rad) of URDF joint values ``q`` (..., 6)."""
        q = np.asarray(q, dtype=float)
        return q if all(s == 1.0 for s in self.joint_sign) else q * np.asarray(self.joint_sign)

    def arrays(self) -> tuple[Array, Array, Array, Array]:
        """``(a, d, alpha, theta_offset)`` as float arrays."""
        return (
            np.asarray(self.a_m, float),
            np.asarray(self.d_m, float),
            np.asarray(self.alpha_rad, float),
            np.asarray(self.theta_offset_rad, float),
        )

    def with_lengths(self, a_m: Iterable[float], d_m: Iterable[float]) -> DHTable:
        """A copy with other link lengths (m)."""
        return replace(self, a_m=tuple(map(float, a_m)), d_m=tuple(map(float, d_m)))

    def with_offsets(self, theta_offset_rad: Iterable[float]) -> DHTable:
        """A copy with other joint offsets (rad)."""
        return replace(self, theta_offset_rad=tuple(map(float, theta_offset_rad)))


@lru_cache(maxsize=64)
def _constant_rows(table: DHTable) -> tuple[Array, Array, Array, Array, Array]:
    """``(a, theta offset, cos alpha, sin alpha, rows 2-3 of every link transform)`` of a table."""
    a, d, alpha, offset = table.arrays()
    ca, sa = np.cos(alpha), np.sin(alpha)
    rows = np.zeros((6, 2, 4))
    rows[:, 0, 1], rows[:, 0, 2], rows[:, 0, 3] = sa, ca, d
    rows[:, 1, 3] = 1.0
    return a, offset, ca, sa, rows


def _rotating_rows(T: Array, theta: Array, a: ArrayLike, ca: Array, sa: Array) -> None:
    """Fill rows 0-1 of link transforms ``T`` (..., 6, 4, 4), the part that turns with theta."""
    ct, st = np.cos(theta), np.sin(theta)
    T[..., 0, 0] = ct
    T[..., 0, 1] = -st * ca
    T[..., 0, 2] = st * sa
    T[..., 0, 3] = a * ct
    T[..., 1, 0] = st
    T[..., 1, 1] = ct * ca
    T[..., 1, 2] = -ct * sa
    T[..., 1, 3] = a * st


def link_transforms(table: DHTable, q: ArrayLike) -> Array:
    """Per-link transforms ``T_{i-1,i}``, shape ``(..., 6, 4, 4)``, for joints ``q`` (..., 6)."""
    a, offset, ca, sa, rows = _constant_rows(table)
    theta = table.joint_values(q) + offset
    T = np.empty((*theta.shape, 4, 4))
    _rotating_rows(T, theta, a, ca, sa)
    T[..., 2:, :] = rows
    return T


def link_transforms_arrays(
    a: ArrayLike, d: ArrayLike, alpha: ArrayLike, theta_offset: ArrayLike, q: ArrayLike
) -> Array:
    """Per-link transforms ``(..., 6, 4, 4)`` for D-H arrays that may differ per row.

    ``a``, ``d``, ``theta_offset`` (m, m, rad) broadcast against ``q`` (..., 6); ``alpha`` is (6,).
    """
    theta = np.asarray(q, dtype=float) + theta_offset
    ca, sa = np.cos(alpha), np.sin(alpha)
    shape = np.broadcast_shapes(theta.shape, np.shape(a), np.shape(d))
    T = np.zeros((*shape, 4, 4))
    _rotating_rows(T, np.broadcast_to(theta, shape), a, ca, sa)
    T[..., 2, 1] = sa
    T[..., 2, 2] = ca
    T[..., 2, 3] = d
    T[..., 3, 3] = 1.0
    return T


def chain(T_links: Array) -> Array:
    """Product ``T_01 @ T_12 @ ... @ T_56`` of per-link transforms (..., 6, 4, 4)."""
    T = T_links[..., 0, :, :] @ T_links[..., 1, :, :]
    for i in range(2, 6):
        T = T @ T_links[..., i, :, :]
    return T


def fk_dh(table: DHTable, q: ArrayLike) -> Array:
    """``T_base_tool0`` from the D-H table; ``q`` (6,) or (N, 6) gives (4, 4) or (N, 4, 4)."""
    return chain(link_transforms(table, q))


def point_dh(table: DHTable, q: ArrayLike, p_tool0: ArrayLike) -> Array:
    """Position (..., 3) in ``base_link`` of the point ``p_tool0`` (3,) fixed in ``tool0`` (m).

    The same value as ``(fk_dh(table, q) @ [*p_tool0, 1])[..., :3]`` (to rounding), about ten
    times faster for many configurations: the point is carried through the links from the
    last to the first (a handful of array operations per link, no 4x4 products).
    """
    a, offset, ca, sa, rows = _constant_rows(table)
    d = rows[:, 0, 3]
    theta = np.asarray(table.joint_values(q), dtype=float) + offset
    ct, st = np.cos(theta), np.sin(theta)
    x, y, z = (np.full(theta.shape[:-1], float(c)) for c in np.asarray(p_tool0, dtype=float))
    for i in range(5, -1, -1):  # p_{i-1} = Rz(theta) Tz(d) Tx(a) Rx(alpha) p_i
        y, z = ca[i] * y - sa[i] * z, sa[i] * y + ca[i] * z + d[i]
        x = x + a[i]
        x, y = ct[..., i] * x - st[..., i] * y, st[..., i] * x + ct[..., i] * y
    return np.stack([x, y, z], axis=-1)


def fk_dh_arrays(
    a: ArrayLike, d: ArrayLike, alpha: ArrayLike, theta_offset: ArrayLike, q: ArrayLike
) -> Array:
    """``T_base_tool0`` (..., 4, 4) for D-H arrays that may differ per row (see ``fk_dh``).

    ``q`` are D-H joint variables (``DHTable.joint_values`` of URDF values).
    """
    return chain(link_transforms_arrays(a, d, alpha, theta_offset, q))


def fk_dh_frames(table: DHTable, q: ArrayLike) -> Array:
    """All D-H frames ``T_base_i`` for i = 0..6, shape ``(..., 7, 4, 4)``."""
    T_links = link_transforms(table, q)
    shape = T_links.shape[:-3]
    out = np.zeros((*shape, 7, 4, 4))
    out[..., 0, :, :] = np.eye(4)
    for i in range(6):
        out[..., i + 1, :, :] = out[..., i, :, :] @ T_links[..., i, :, :]
    return out
