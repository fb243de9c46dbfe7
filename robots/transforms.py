"""Homogeneous transforms and the pose notations used in files.

A transform ``T_a_b`` is a 4x4 array mapping coordinates in frame ``b`` into
frame ``a``: ``p_a = T_a_b @ p_b``. Roll-pitch-yaw angles follow ROS REP-103:
``R = Rz(yaw) @ Ry(pitch) @ Rx(roll)`` (fixed axes x, y, z). Quaternions are
stored ``[x, y, z, w]``. All lengths in metres, angles in radians.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial.transform import Rotation

Array = NDArray[np.float64]


def rpy_to_matrix(rpy: ArrayLike) -> Array:
    """Rotation matrix of fixed-axis roll, pitch, yaw angles (rad)."""
    return Rotation.from_euler("xyz", np.asarray(rpy, dtype=float)).as_matrix()


def matrix_to_rpy(R: ArrayLike) -> Array:
    """Fixed-axis roll, pitch, yaw (rad) of a rotation matrix."""
    return Rotation.from_matrix(np.asarray(R, dtype=float)).as_euler("xyz")


def make_transform(R: ArrayLike | None = None, t: ArrayLike | None = None) -> Array:
    """4x4 transform from a rotation matrix and a translation (m)."""
    T = np.eye(4)
    if R is not None:
        T[:3, :3] = np.asarray(R, dtype=float)
    if t is not None:
        T[:3, 3] = np.asarray(t, dtype=float)
    return T


def pose_to_matrix(
    xyz: ArrayLike, rpy: ArrayLike | None = None, quat_xyzw: ArrayLike | None = None
) -> Array:
    """4x4 transform from a position (m) and either rpy (rad) or a quaternion [x, y, z, w]."""
    if quat_xyzw is not None:
        R = Rotation.from_quat(np.asarray(quat_xyzw, dtype=float)).as_matrix()
    else:
        R = rpy_to_matrix(rpy if rpy is not None else (0.0, 0.0, 0.0))
    return make_transform(R, xyz)


def matrix_to_pose(T: ArrayLike) -> dict[str, list[float]]:
    """File notation ``{xyz, rpy, quat_xyzw}`` of a 4x4 transform."""
    T = np.asarray(T, dtype=float)
    return {
        "xyz": [float(v) for v in T[:3, 3]],
        "rpy": [float(v) for v in matrix_to_rpy(T[:3, :3])],
        "quat_xyzw": [float(v) for v in Rotation.from_matrix(T[:3, :3]).as_quat()],
    }


def invert(T: ArrayLike) -> Array:
    """Inverse of a rigid 4x4 transform."""
    T = np.asarray(T, dtype=float)
    Ti = np.eye(4)
    Ti[:3, :3] = T[:3, :3].T
    Ti[:3, 3] = -T[:3, :3].T @ T[:3, 3]
    return Ti


def frame_from_z_axis(origin: ArrayLike, z_axis: ArrayLike, roll: float = 0.0) -> Array:
    """A frame at ``origin`` whose z axis is ``z_axis``, rotated by ``roll`` (rad) about it.

    The x axis at ``roll = 0`` is the component of the world x (or y, if z is
    nearly parallel to x) orthogonal to z, so the result is deterministic.
    """
    z = np.asarray(z_axis, dtype=float)
    z = z / np.linalg.norm(z)
    ref = np.array([1.0, 0.0, 0.0]) if abs(z[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    x = ref - z * (ref @ z)
    x /= np.linalg.norm(x)
    y = np.cross(z, x)
    c, s = np.cos(roll), np.sin(roll)
    R = np.column_stack((c * x + s * y, -s * x + c * y, z))
    return make_transform(R, origin)


def rotation_angle(R_a: ArrayLike, R_b: ArrayLike) -> float:
    """Angle (rad) of the relative rotation between two rotation matrices."""
    R = np.asarray(R_a, dtype=float).T @ np.asarray(R_b, dtype=float)
    return float(np.arccos(np.clip((np.trace(R) - 1.0) / 2.0, -1.0, 1.0)))


# --- SO(3): the Lie-group helpers used by the adjustments (once, here) ------------------------
def skew(v: ArrayLike) -> Array:
    """Cross-product matrices ``[v]x`` (..., 3, 3) of vectors ``v`` (..., 3):
    ``[v]x @ u = v x u``."""
    v = np.asarray(v, dtype=float)
    S = np.zeros((*v.shape[:-1], 3, 3))
    S[..., 0, 1], S[..., 0, 2] = -v[..., 2], v[..., 1]
    S[..., 1, 0], S[..., 1, 2] = v[..., 2], -v[..., 0]
    S[..., 2, 0], S[..., 2, 1] = -v[..., 1], v[..., 0]
    return S


def so3_exp(w: ArrayLike) -> Array:
    """Rotation matrices (..., 3, 3) of rotation vectors ``w`` (..., 3) rad (Rodrigues)."""
    w = np.asarray(w, dtype=float)
    th = np.linalg.norm(w, axis=-1)[..., None, None]
    K = skew(w / np.maximum(th[..., 0], 1e-300))
    return np.eye(3) + np.sin(th) * K + (1.0 - np.cos(th)) * (K @ K)


def so3_log(R: ArrayLike) -> Array:
    """Rotation vectors (..., 3) rad of rotation matrices ``R`` (..., 3, 3)."""
    R = np.asarray(R, dtype=float)
    flat = R.reshape(-1, 3, 3)
    return Rotation.from_matrix(flat).as_rotvec().reshape((*R.shape[:-2], 3))


def so3_left_jacobian(w: ArrayLike) -> Array:
    """Left Jacobian (3, 3) of SO(3) at the rotation vector ``w`` (rad):
    ``exp(w + e) = exp(J_l e) exp(w)`` to first order in ``e``."""
    w = np.asarray(w, dtype=float)
    th = float(np.linalg.norm(w))
    W = skew(w)
    if th < 1e-8:
        return np.eye(3) + 0.5 * W
    return np.eye(3) + (1 - np.cos(th)) / th**2 * W + (th - np.sin(th)) / th**3 * W @ W


def kabsch(P: ArrayLike, Q: ArrayLike) -> tuple[Array, Array, Array]:
    """Least-squares rigid motion with ``Q ~ R P + t``: ``P (k, 3)`` nominal, ``Q (N, k, 3)``
    measured; returns R ``(N, 3, 3)``, t ``(N, 3)``, RMS residual ``(N,)`` (m)."""
    P, Q = np.asarray(P, dtype=float), np.asarray(Q, dtype=float)
    p0, q0 = P.mean(axis=0), Q.mean(axis=1)
    H = np.einsum("ki,nkj->nij", P - p0, Q - q0[:, None, :])
    U, _, Vt = np.linalg.svd(H)
    d = np.sign(np.linalg.det(np.einsum("nji,nkj->nik", Vt, U)))
    D = np.zeros((len(d), 3, 3))
    D[:, 0, 0] = D[:, 1, 1] = 1.0
    D[:, 2, 2] = d
    R = np.einsum("nji,njk,nlk->nil", Vt, D, U)
    t = q0 - R @ p0
    res = Q - (np.einsum("nij,kj->nki", R, P) + t[:, None, :])
    return R, t, np.sqrt(np.mean(np.sum(res**2, axis=2), axis=1))
