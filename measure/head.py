"""The stereo head (TCP) frame.

``T_left_head`` maps head coordinates into the left camera optical frame. The head frame:

- origin midway between the two camera centres;
- z along the bisector of the two optical axes (pointing forward, toward where they meet);
- x toward the right camera (the baseline, made orthogonal to z);
- y = z × x (so y points "down" like the cameras' y).

The robot's tool TCP is this frame; a hole is viewed with its centre at ``standoff_m``
(0.25 m for the standard head) along the head z axis and its normal along -z.
"""

from __future__ import annotations

import numpy as np

from measure.calibration import StereoCalibration


def head_frame(stereo: StereoCalibration) -> np.ndarray:
    """The 4×4 transform ``T_left_head`` (metres) of the stereo head frame (see module doc)."""
    c_right = stereo.right_center_in_left
    z_left = np.array([0.0, 0.0, 1.0])
    z_right = stereo.R.T @ np.array([0.0, 0.0, 1.0])
    z = z_left + z_right
    z /= np.linalg.norm(z)
    x = c_right - (c_right @ z) * z
    x /= np.linalg.norm(x)
    y = np.cross(z, x)
    T = np.eye(4)
    T[:3, 0], T[:3, 1], T[:3, 2] = x, y, z
    T[:3, 3] = 0.5 * c_right
    return T


def convergence_distance_m(stereo: StereoCalibration) -> float:
    """Distance (metres) along the head z axis to where the optical axes pass closest."""
    T = head_frame(stereo)
    origin, z = T[:3, 3], T[:3, 2]
    # closest point of the left optical axis (through 0 along e_z) to the right optical axis
    c_r = stereo.right_center_in_left
    d_l = np.array([0.0, 0.0, 1.0])
    d_r = stereo.R.T @ d_l
    w0 = -c_r
    a, b, c = d_l @ d_l, d_l @ d_r, d_r @ d_r
    d, e = d_l @ w0, d_r @ w0
    denom = a * c - b * b
    if abs(denom) < 1e-12:
        return float("inf")
    s = (b * e - c * d) / denom
    t = (a * e - b * d) / denom
    mid = 0.5 * (s * d_l + c_r + t * d_r)
    return float((mid - origin) @ z)
