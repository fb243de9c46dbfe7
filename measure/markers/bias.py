"""The perspective bias of a circle's image: the centre of the ellipse is not the image of the
circle's centre.

A circle of radius ``r`` about ``C`` in the plane spanned by unit vectors ``e1``, ``e2`` is the
conic ``diag(1, 1, -r²)`` of the plane coordinates; the pinhole maps the plane to ideal pixels by
the homography ``H = K [e1 e2 C]``, so the image is the conic ``A = H⁻ᵀ diag(1, 1, -r²) H⁻¹``,
whose centre solves ``A[:2, :2] c = -A[:2, 2]``. The circle's centre projects to ``H (0, 0, 1)``.
Exact for any pose with the circle wholly in front of the camera.
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
    C = np.asarray(center_cam_m, dtype=float).reshape(3)
    if C[2] <= 0:
        raise ValueError(f"circle centre must be in front of the camera (z > 0), got z = {C[2]}")
    A = circle_image_conic(K, C, normal_cam, radius_m)
    p = np.asarray(K, dtype=float) @ C
    return conic_center(A) - p[:2] / p[2]
