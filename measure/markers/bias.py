"""The perspective bias of a circle's image: the centre of the ellipse is not the image of the
circle's centre.

A circle of radius ``r`` about ``C`` in the plane spanned by unit vectors ``e1``, ``e2`` is the
conic ``diag(1, 1, -r²)`` of the plane coordinates; the pinhole maps the plane to ideal pixels by
the homography ``H = K [e1 e2 C]``, so the image is the conic ``A = H⁻ᵀ diag(1, 1, -r²) H⁻¹``,
whose centre solves ``A[:2, :2] c = -A[:2, 2]``. The circle's centre projects to ``H (0, 0, 1)``.
Exact for any pose with the circle wholly in front of the camera.

Closed form (:func:`circle_center_bias_many_px`): the ellipse's centre is the pole of the line
at infinity, ``c ~ A⁻¹ (0, 0, 1) = H diag(1, 1, -1/r²) Hᵀ (0, 0, 1)``; with ``Hᵀ (0, 0, 1) =
(e1_z, e2_z, C_z)`` and ``e1 e1_z + e2 e2_z = z - n n_z`` (``z`` the optical axis, ``n`` the unit
normal) it is the projection of the point ``C C_z - r² (z - n n_z)``: no plane axes, no
inverse, any number of circles at once.
"""

from __future__ import annotations

import numpy as np


def _plane_axes(normal: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    ref = np.array([1.0, 0.0, 0.0]) if abs(normal[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    e1 = np.cross(normal, ref)
    e1 /= np.linalg.norm(e1)
    return e1, np.cross(normal, e1)


def circle_image_conic(
    K: np.ndarray, center_cam_m: np.ndarray, normal_cam: np.ndarray, radius_m: float
) -> np.ndarray:
    """The 3 × 3 symmetric conic (ideal pixels, homogeneous) of a circle's pinhole image."""
    C = np.asarray(center_cam_m, dtype=float).reshape(3)
    n = np.asarray(normal_cam, dtype=float).reshape(3)
    n = n / np.linalg.norm(n)
    e1, e2 = _plane_axes(n)
    H = np.asarray(K, dtype=float) @ np.column_stack([e1, e2, C])
    Hi = np.linalg.inv(H)
    return Hi.T @ np.diag([1.0, 1.0, -(float(radius_m) ** 2)]) @ Hi


def conic_center(A: np.ndarray) -> np.ndarray:
    """Centre (2,) of the ellipse with conic matrix ``A`` (3 × 3 symmetric)."""
    return np.linalg.solve(A[:2, :2], -A[:2, 2])


def circle_center_bias_many_px(
    K: np.ndarray, centers_cam_m: np.ndarray, normals_cam: np.ndarray, radii_m: np.ndarray
) -> np.ndarray:
    """:func:`circle_center_bias_px` of ``n`` circles at once (closed form, module doc):
    centres (n, 3) m in the camera frame, every one in front of it; normals (n, 3), either sign,
    any length; radii (n,) m. Returns (n, 2) ideal pixels."""
    C = np.asarray(centers_cam_m, dtype=float).reshape(-1, 3)
    n = np.asarray(normals_cam, dtype=float).reshape(-1, 3)
    r = np.broadcast_to(np.asarray(radii_m, dtype=float), (len(C),))
    if len(C) and not np.all(C[:, 2] > 0):
        z = C[np.argmin(C[:, 2]), 2]
        raise ValueError(f"circle centre must be in front of the camera (z > 0), got z = {z}")
    n = n / np.linalg.norm(n, axis=1, keepdims=True)
    v = C * C[:, 2:3] + (r**2)[:, None] * (n * n[:, 2:3])
    v[:, 2] -= r**2
    K = np.asarray(K, dtype=float)
    ev, pc = v @ K.T, C @ K.T
    return ev[:, :2] / ev[:, 2:3] - pc[:, :2] / pc[:, 2:3]


def circle_center_bias_px(
    K: np.ndarray, center_cam_m: np.ndarray, normal_cam: np.ndarray, radius_m: float
) -> np.ndarray:
    """Ideal-pixel offset (2,): centre of a circle's image (the ellipse) minus the projection of
    the circle's centre.

    Args:
        K: camera matrix (3 × 3, pixels).
        center_cam_m: the circle's centre in the camera frame (m), in front of the camera.
        normal_cam: the circle's plane normal in the camera frame (either sign).
        radius_m: the circle's radius (m).

    Subtract it from a detected ideal ellipse centre to get the projected centre.
    """
    return circle_center_bias_many_px(K, center_cam_m, normal_cam, np.array([radius_m]))[0]
