"""D-H error parameters: the calibrated table, its forward kinematics and the twist of each term.

The error vector ``delta`` has 24 numbers, joint by joint ``(a_m, d_m, alpha_rad, theta_rad)``
(term ``4 * (joint - 1) + k``), added to the rows of a nominal classic D-H table
(:mod:`robots.dh`): ``a_i + da_i``, ``d_i + dd_i``, ``alpha_i + dalpha_i``,
``theta_offset_i + dtheta_i``. Names: ``a1_m``, ``d1_m``, ``alpha1_rad``, ``theta1_rad``, ...

The derivative of ``T_base_tool0`` with respect to a term is a spatial twist in ``base_link``,
``dT = [v, w]^ @ T`` (``v`` m per unit, ``w`` rad per unit), because link i is
``Rz(theta) Tz(d) Tx(a) Rx(alpha)``: ``theta_i`` turns about ``z_{i-1}`` through ``o_{i-1}``,
``d_i`` slides along ``z_{i-1}``, ``a_i`` slides along ``x_i`` and ``alpha_i`` turns about ``x_i``
through ``o_i`` (frames of the table with the errors applied).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robots.dh import DHTable, chain, link_transforms_arrays

Array = NDArray[np.float64]

#: the four terms of each joint, in vector order (units in the name)
DH_TERMS: tuple[str, ...] = ("a_m", "d_m", "alpha_rad", "theta_rad")
#: length of the error vector
N_DH_TERMS = 24


def term_names() -> tuple[str, ...]:
    """The 24 term names in vector order: ``a1_m, d1_m, alpha1_rad, theta1_rad, a2_m, ...``."""
    return tuple(f"{t.split('_')[0]}{j}_{t.split('_')[1]}" for j in range(1, 7) for t in DH_TERMS)


def _check(delta: ArrayLike) -> Array:
    arr = np.asarray(delta, dtype=float).reshape(-1)
    if arr.shape != (N_DH_TERMS,) or not np.all(np.isfinite(arr)):
        raise ValueError(f"D-H error vector must be 24 finite numbers, got shape {arr.shape}")
    return arr


def error_arrays(table: DHTable, delta: ArrayLike) -> tuple[Array, Array, Array, Array]:
    """``(a, d, alpha, theta_offset)`` (m, m, rad, rad; each (6,)) of ``table`` plus ``delta``."""
    e = _check(delta).reshape(6, 4)
    a, d, alpha, offset = table.arrays()
    return a + e[:, 0], d + e[:, 1], alpha + e[:, 2], offset + e[:, 3]


def calibrated_table(table: DHTable, delta: ArrayLike) -> DHTable:
    """The D-H table with the errors added (same joint signs), for any user of :mod:`robots.dh`."""
    a, d, alpha, offset = error_arrays(table, delta)
    return DHTable(
        a_m=tuple(map(float, a)),
        d_m=tuple(map(float, d)),
        alpha_rad=tuple(map(float, alpha)),
        theta_offset_rad=tuple(map(float, offset)),
        joint_sign=table.joint_sign,
    )


def _links(table: DHTable, delta: ArrayLike, q: ArrayLike) -> Array:
    a, d, alpha, offset = error_arrays(table, delta)
    return link_transforms_arrays(a, d, alpha, offset, table.joint_values(np.asarray(q, float)))


def fk_with_errors(table: DHTable, delta: ArrayLike, q: ArrayLike) -> Array:
    """``T_base_tool0`` of joints ``q`` (URDF values, rad; (6,) or (N, 6)) with the errors."""
    return chain(_links(table, delta, q))


def frames_with_errors(table: DHTable, delta: ArrayLike, q: ArrayLike) -> Array:
    """All frames ``T_base_i``, i = 0..6, shape ``(..., 7, 4, 4)``, with the errors applied."""
    T_links = _links(table, delta, q)
    out = np.zeros((*T_links.shape[:-3], 7, 4, 4))
    out[..., 0, :, :] = np.eye(4)
    for i in range(6):
        out[..., i + 1, :, :] = out[..., i, :, :] @ T_links[..., i, :, :]
    return out


def dh_error_twists(table: DHTable, delta: ArrayLike, q: ArrayLike) -> Array:
    """Spatial twists ``(..., 24, 6)`` ``[v (m), w (rad)]`` in ``base_link`` of each term.

    Row ``k`` is ``dT_base_tool0 / d delta_k`` written as ``[v, w]`` with
    ``dT = [[skew(w), v], [0, 0]] @ T_base_tool0`` (first order, at ``delta``).
    """
    F = frames_with_errors(table, delta, q)
    out = np.zeros((*F.shape[:-3], N_DH_TERMS, 6))
    for i in range(6):
        o_prev, z_prev = F[..., i, :3, 3], F[..., i, :3, 2]
        o_i, x_i = F[..., i + 1, :3, 3], F[..., i + 1, :3, 0]
        k = 4 * i
        out[..., k + 0, :3] = x_i  # a: slide along x_i
        out[..., k + 1, :3] = z_prev  # d: slide along z_{i-1}
        out[..., k + 2, :3] = np.cross(o_i, x_i)  # alpha: turn about x_i through o_i
        out[..., k + 2, 3:] = x_i
        out[..., k + 3, :3] = np.cross(o_prev, z_prev)  # theta: turn about z_{i-1}
        out[..., k + 3, 3:] = z_prev
    return out
