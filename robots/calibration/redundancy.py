"""D-H error terms that other unknowns of a calibration absorb, known from the table's shape.

With the pose of the target (or of anything the cameras see) in ``base_link`` estimated, and
the pose of the camera in ``tool0`` estimated, some error terms change nothing that can be
observed:

- ``d1`` and ``theta1`` move every link along and about ``z_0``: the same as moving the base;
- the last link's ``a6`` and ``alpha6`` are a constant transform after every joint, and so
  are ``d6`` and ``theta6`` when the nominal ``a6`` and ``alpha6`` are zero (an OPW arm):
  the hand-eye absorbs them;
- for consecutive parallel axes (``alpha_i`` = 0 or pi), ``d_i`` and ``d_{i+1}`` slide along the
  same direction: only their sum is seen, so ``d_{i+1}`` is fixed.

The numerical rank of the data (:mod:`cell.calibration.estimate.identifiability`) may name more.
"""

from __future__ import annotations

import numpy as np

from robots.calibration.dh_errors import term_names
from robots.dh import DHTable

#: an angle (rad) this close to 0 or pi counts as parallel / zero
_PARALLEL_TOL_RAD = 1e-6


def _is_zero_angle(angle: float) -> bool:
    return abs(np.sin(angle)) < _PARALLEL_TOL_RAD


def structural_redundancies(
    table: DHTable, base_pose_free: bool = True, tool_pose_free: bool = True
) -> dict[str, str]:
    """Term name -> reason, for every term redundant with a free base or tool pose.

    ``base_pose_free``: a pose fixed in ``base_link`` (the target's) is estimated too;
    ``tool_pose_free``: a pose fixed in ``tool0`` (the camera's) is estimated too.
    """
    names = term_names()
    a, _d, alpha, _off = table.arrays()
    out: dict[str, str] = {}
    if base_pose_free:
        for k in (1, 3):
            out[names[k]] = (
                "redundant with the target's pose in the base (moves the base along/about z0)"
            )
    if tool_pose_free:
        out[names[20]] = "redundant with the hand-eye (a constant transform after joint 6)"
        out[names[22]] = "redundant with the hand-eye (a constant transform after joint 6)"
        if abs(a[5]) < 1e-12 and _is_zero_angle(alpha[5]):
            reason = "redundant with the hand-eye (nominal a6 = alpha6 = 0: a constant transform)"
            out[names[21]] = reason
            out[names[23]] = reason
    for j in range(1, 6):  # alpha_j = 0 or pi: z_{j-1} parallel to z_j
        if _is_zero_angle(alpha[j - 1]):
            name = names[4 * j + 1]  # d_{j+1}
            out.setdefault(
                name,
                f"redundant with d{j}: axes {j} and {j + 1} are parallel, only the sum of the "
                "slides along them is seen",
            )
    return out


def _rz_tz(theta_rad: float, d_m: float) -> np.ndarray:
    c, s = np.cos(theta_rad), np.sin(theta_rad)
    T = np.eye(4)
    T[:2, :2] = [[c, -s], [s, c]]
    T[2, 3] = d_m
    return T


def _tx_rx(a_m: float, alpha_rad: float) -> np.ndarray:
    c, s = np.cos(alpha_rad), np.sin(alpha_rad)
    T = np.eye(4)
    T[1:3, 1:3] = [[c, -s], [s, c]]
    T[0, 3] = a_m
    return T


def fold_redundant(table: DHTable, delta: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The structurally redundant terms of ``delta`` moved into a base and a tool transform.

    Returns ``(delta_folded, T_base_base', T_tool0'_tool0)`` with
    ``fk_with_errors(table, delta, q) == C @ fk_with_errors(table, delta_folded, q) @ E``
    for every ``q``: exact for ``d1, theta1`` (``C = Rz(theta1) Tz(d1)``) and for the joint-6
    terms of an arm with nominal ``a6 = alpha6 = 0`` (``E = Rz(theta6) Tz(d6) Tx(a6) Rx(alpha6)``);
    ``d_{j+1}`` of parallel axes is added to ``d_j`` (exact when ``alpha_j`` with its error is
    0, else to second order: about 0.1 um for 0.3 mm and 0.02 deg errors). A truth compares
    with a calibration that fixed those terms as ``T_base_target' = inv(C) @ T_base_target`` and
    ``T_tool0_camera' = E @ T_tool0_camera``.
    """
    e = np.array(delta, dtype=float).reshape(6, 4).copy()
    a, _d, alpha, _off = table.arrays()
    C = _rz_tz(e[0, 3], e[0, 1])
    e[0, 1] = e[0, 3] = 0.0
    E = np.eye(4)
    if abs(a[5]) < 1e-12 and _is_zero_angle(alpha[5]):
        E = _rz_tz(e[5, 3], e[5, 1]) @ _tx_rx(e[5, 0], e[5, 2])
        e[5] = 0.0
    for j in range(1, 6):
        if _is_zero_angle(alpha[j - 1]):
            e[j - 1, 1] += e[j, 1]
            e[j, 1] = 0.0
    return e.reshape(-1), C, E
