"""Parameter covariance of a (stereo) calibration from the Jacobian of its reprojection residual.

OpenCV's ``calibrateCameraExtended`` reports standard deviations of one camera's intrinsics, and
``stereoCalibrateExtended`` per-view errors but no standard deviations. This module linearises
the stereo problem at its solution and returns the covariance of every free parameter,
``σ² (JᵀJ)⁻¹`` with ``σ² = Σ r² / (M − P)`` (M residuals, P parameters), the same estimate
OpenCV uses for one camera. Parameters, in this order:

- per camera (left, then right): ``fx, fy, cx, cy`` (px) and the free distortion terms
  ``k1, k2, p1, p2`` (k3 is held at its value, as the calibration fixes it);
- the left→right extrinsics: rotation vector ``r`` (rad) and ``T`` (m);
- per view: the plate pose in the left camera ``(r_i, t_i)``.

Residuals: each view's left reprojection through ``(r_i, t_i)`` and right reprojection through
the composed pose ``R·R_i, R·t_i + T`` (``cv2.composeRT`` gives its derivatives); both from
``cv2.projectPoints`` with its analytic Jacobian.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

#: columns of cv2.projectPoints' Jacobian: rvec 0:3, tvec 3:6, f 6:8, c 8:10, dist 10:15
_FREE_INTRINSICS = [6, 7, 8, 9, 10, 11, 12, 13]  # fx fy cx cy k1 k2 p1 p2
N_INTR = len(_FREE_INTRINSICS)


@dataclass(frozen=True)
class Camera:
    """One camera's intrinsics: ``K`` (3×3, px) and ``dist`` (k1 k2 p1 p2 k3)."""

    K: np.ndarray
    dist: np.ndarray


@dataclass(frozen=True)
class ParameterCovariance:
    """Covariance of a calibration's free parameters (order: see the module docstring).

    Attributes:
        cov: P×P covariance (units of the parameters, squared).
        sigma_px: the residual standard deviation ``sqrt(Σ r² / (M − P))`` (pixels).
        n_residuals, n_params: M and P.
        stereo: whether the extrinsics (and a second camera) are in it.
    """

    cov: np.ndarray
    sigma_px: float
    n_residuals: int
    n_params: int
    stereo: bool

    @property
    def std(self) -> np.ndarray:
        """One-sigma of every parameter."""
        return np.sqrt(np.clip(np.diag(self.cov), 0.0, None))

    def intrinsics_std(self, side: str = "left") -> tuple[np.ndarray, np.ndarray]:
        """``(fx, fy, cx, cy)`` std (px) and ``(k1, k2, p1, p2, k3)`` std (k3 fixed: 0)."""
        i0 = 0 if side == "left" else N_INTR
        s = self.std[i0 : i0 + N_INTR]
        return s[:4].copy(), np.concatenate([s[4:8], [0.0]])

    def extrinsics_std(self) -> tuple[np.ndarray, np.ndarray]:
        """Std of the left→right rotation vector (rad) and translation (m)."""
        if not self.stereo:
            raise ValueError("a single-camera covariance has no extrinsics")
        s = self.std[2 * N_INTR : 2 * N_INTR + 6]
        return s[:3].copy(), s[3:].copy()


def _project(obj: np.ndarray, rvec: np.ndarray, tvec: np.ndarray, cam: Camera):
    px, jac = cv2.projectPoints(obj, rvec, tvec, cam.K, cam.dist)
    return px.reshape(-1, 2), jac


def stereo_covariance(
    obj_m: np.ndarray,
    img_left: list[np.ndarray],
    img_right: list[np.ndarray],
    left: Camera,
    right: Camera,
    R: np.ndarray,
    T: np.ndarray,
    rvecs: list[np.ndarray],
    tvecs: list[np.ndarray],
) -> ParameterCovariance:
    """Covariance of a stereo calibration at its solution.

    Args:
        obj_m: plate points (N, 3, metres). img_left / img_right: per view (N, 2) pixels.
        left, right: the solved cameras. R, T: left→right (``X_r = R X_l + T``, metres).
        rvecs, tvecs: per view the plate pose in the left camera (as the solver returns).
    """
    n = len(img_left)
    obj = np.asarray(obj_m, np.float64).reshape(-1, 3)
    npts = len(obj)
    P = 2 * N_INTR + 6 + 6 * n
    M = 2 * 2 * npts * n
    J = np.zeros((M, P))
    res = np.zeros(M)
    r_ext = cv2.Rodrigues(np.asarray(R, np.float64))[0]
    t_ext = np.asarray(T, np.float64).reshape(3, 1)
    ext = slice(2 * N_INTR, 2 * N_INTR + 6)
    for i in range(n):
        ri = np.asarray(rvecs[i], np.float64).reshape(3, 1)
        ti = np.asarray(tvecs[i], np.float64).reshape(3, 1)
        pose = slice(2 * N_INTR + 6 + 6 * i, 2 * N_INTR + 12 + 6 * i)
        # left image
        rows = slice(4 * npts * i, 4 * npts * i + 2 * npts)
        px, jac = _project(obj, ri, ti, left)
        res[rows] = (px - img_left[i].reshape(-1, 2)).ravel()
        J[rows, 0:N_INTR] = jac[:, _FREE_INTRINSICS]
        J[rows, pose] = jac[:, 0:6]
        # right image through the composed pose
        rows = slice(4 * npts * i + 2 * npts, 4 * npts * (i + 1))
        r3, t3, dr3dr1, dr3dt1, dr3dr2, dr3dt2, dt3dr1, dt3dt1, dt3dr2, dt3dt2 = cv2.composeRT(
            ri, ti, r_ext, t_ext
        )
        px, jac = _project(obj, r3, t3, right)
        res[rows] = (px - img_right[i].reshape(-1, 2)).ravel()
        J[rows, N_INTR : 2 * N_INTR] = jac[:, _FREE_INTRINSICS]
        d_r3, d_t3 = jac[:, 0:3], jac[:, 3:6]
        d_pose = np.hstack([d_r3 @ dr3dr1 + d_t3 @ dt3dr1, d_r3 @ dr3dt1 + d_t3 @ dt3dt1])
        d_ext = np.hstack([d_r3 @ dr3dr2 + d_t3 @ dt3dr2, d_r3 @ dr3dt2 + d_t3 @ dt3dt2])
        J[rows, pose] = d_pose
        J[rows, ext] = d_ext
    return _covariance(J, res, stereo=True)


def mono_covariance(
    obj_m: np.ndarray,
    img: list[np.ndarray],
    cam: Camera,
    rvecs: list[np.ndarray],
    tvecs: list[np.ndarray],
) -> ParameterCovariance:
    """Covariance of one camera's calibration (parameters: intrinsics, then per-view poses);
    the same estimate as ``cv2.calibrateCameraExtended``'s standard deviations."""
    n = len(img)
    obj = np.asarray(obj_m, np.float64).reshape(-1, 3)
    npts = len(obj)
    J = np.zeros((2 * npts * n, N_INTR + 6 * n))
    res = np.zeros(2 * npts * n)
    for i in range(n):
        rows = slice(2 * npts * i, 2 * npts * (i + 1))
        px, jac = _project(obj, np.asarray(rvecs[i], float), np.asarray(tvecs[i], float), cam)
        res[rows] = (px - img[i].reshape(-1, 2)).ravel()
        J[rows, :N_INTR] = jac[:, _FREE_INTRINSICS]
        J[rows, N_INTR + 6 * i : N_INTR + 6 * (i + 1)] = jac[:, 0:6]
    return _covariance(J, res, stereo=False)


def _covariance(J: np.ndarray, res: np.ndarray, stereo: bool) -> ParameterCovariance:
    M, P = J.shape
    dof = max(M - P, 1)
    sigma2 = float(res @ res) / dof
    # scale columns for a well-conditioned inverse (pixels vs radians vs metres)
    scale = np.linalg.norm(J, axis=0)
    scale[scale == 0] = 1.0
    Js = J / scale
    cov_s = np.linalg.pinv(Js.T @ Js, rcond=1e-12)
    cov = sigma2 * cov_s / np.outer(scale, scale)
    return ParameterCovariance(
        cov=cov, sigma_px=float(np.sqrt(sigma2)), n_residuals=M, n_params=P, stereo=stereo
    )
