"""The stereo calibration's contribution to a hole's centre and diameter.

The calibration's parameters (each camera's ``fx, fy, cx, cy`` and ``k1, k2, p1, p2, k3``, the
left->right rotation vector and translation: 24 in all) carry one-sigma uncertainties
(:class:`measure.calibration_uncertainty.CalibrationUncertainty`, written by ``holecell
calibrate``). They are propagated to the fitted circle by re-triangulating the measurement's own
edge points under a changed calibration:

1. the inlier edge points (left frame) are projected into both images with the calibration the
   hole was measured with: the matched pixel pairs, as the cameras saw them;
2. for each parameter, the calibration is changed by +-1 sigma, the pairs are undistorted,
   rectified and triangulated again (:func:`measure.triangulate.triangulate`) and the circle is
   refitted; central differences give the sensitivity, and the covariance is
   ``J diag(sigma^2) J^T`` (:func:`jacobian_covariance`, GUM's law of propagation; parameters
   taken as independent, as the file gives no correlations);
3. :func:`monte_carlo_covariance` draws whole calibrations from the same distribution and
   refits with :func:`measure.fit_circle_3d` itself: the second method that checks the first.

The refit of step 2 is the algebraic fit (least-squares plane, then the linear Kasa circle in
it): for points on a circle it has the sensitivity of the orthogonal fit, at a fraction of the
cost. The left camera's pose relative to the TCP is the hand-eye calibration's: this component
moves points within the left camera frame only; the hand-eye's (and the arm's D-H terms')
uncertainty is the budget's ``cell_calibration`` component when the run applies a cell
calibration (:mod:`cell.calibration.use.run_calibration`).

A calibration without an uncertainty block gets :func:`default_uncertainty` (figures of a
careful calibration with a certified target, scaled to the head's focal length and baseline),
and the budget says so.
"""

from __future__ import annotations

import numpy as np

from measure import StereoCalibration, fit_circle_3d
from measure.calibration_uncertainty import CalibrationUncertainty
from measure.triangulate import triangulate

#: default one-sigma figures of a calibration without an uncertainty block: fx, fy, cx, cy (px).
#: The parameters that set the vertical disparity (cy of both cameras, the rotation about the
#: baseline, T.y) are the ones the epipolar constraint pins down (a good calibration leaves
#: about 0.1 px of vertical disparity), so as independent figures they are small; larger ones
#: would describe a head whose matching fails, not one that measures with a larger error.
DEFAULT_K_STD_PX = (0.3, 0.3, 0.25, 0.05)
DEFAULT_DIST_STD = (2e-4, 2e-3, 2e-5, 2e-5, 5e-3)
DEFAULT_RVEC_STD_RAD = (1e-5, 5e-5, 2e-5)
#: translation standard deviation relative to the baseline (x) and absolute (y, z; m)
DEFAULT_T_REL_STD = 5e-5
DEFAULT_T_STD_M = (2e-6, 1e-5)
N_PARAMETERS = 24
#: the Jacobian uses at most this many of the edge points, evenly spread over the contour (the
#: circle's sensitivity to the calibration is smooth along it: 128 points reproduce the
#: figures of 1662 to 0.05 %, at a fifth of the cost)
MAX_JACOBIAN_POINTS = 256
PARAMETER_NAMES = tuple(
    [f"left.{n}" for n in ("fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2", "k3")]
    + [f"right.{n}" for n in ("fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2", "k3")]
    + ["rvec.x", "rvec.y", "rvec.z", "T.x", "T.y", "T.z"]
)


def default_uncertainty(stereo: StereoCalibration) -> CalibrationUncertainty:
    """One-sigma figures for a calibration that states none (documented defaults)."""
    k = np.array(DEFAULT_K_STD_PX)
    d = np.array(DEFAULT_DIST_STD)
    t = np.array([DEFAULT_T_REL_STD * stereo.baseline_m, *DEFAULT_T_STD_M])
    return CalibrationUncertainty(k, d, k.copy(), d.copy(), np.array(DEFAULT_RVEC_STD_RAD), t, 0.0)


def parameter_sigmas(unc: CalibrationUncertainty) -> np.ndarray:
    """The 24 standard deviations in :data:`PARAMETER_NAMES` order."""
    return np.concatenate([unc.K_std_left_px, unc.dist_std_left, unc.K_std_right_px,
                           unc.dist_std_right, unc.rvec_std_rad, unc.T_std_m])  # fmt: skip


def perturbed(stereo: StereoCalibration, delta: np.ndarray) -> StereoCalibration:
    """``stereo`` with the 24 parameters changed by ``delta`` (:data:`PARAMETER_NAMES` order)."""
    import cv2

    def camera(K: np.ndarray, dist: np.ndarray, dk: np.ndarray, dd: np.ndarray):
        K2 = K.copy()
        K2[0, 0] += dk[0]
        K2[1, 1] += dk[1]
        K2[0, 2] += dk[2]
        K2[1, 2] += dk[3]
        d2 = dist.copy()
        d2[:5] += dd[: min(5, len(d2))]
        return K2, d2

    Kl, dl = camera(stereo.K_left, stereo.dist_left, delta[0:4], delta[4:9])
    Kr, dr = camera(stereo.K_right, stereo.dist_right, delta[9:13], delta[13:18])
    rvec = cv2.Rodrigues(stereo.R)[0].ravel() + delta[18:21]
    R = cv2.Rodrigues(rvec)[0]
    return StereoCalibration(stereo.image_size, Kl, dl, Kr, dr, R, stereo.T + delta[21:24],
                             source=stereo.source)  # fmt: skip


def pixel_pairs(stereo: StereoCalibration, points_left_m: np.ndarray) -> tuple[np.ndarray, ...]:
    """Distorted pixels (N, 2) in the left and right image of left-frame points (N, 3)."""
    return stereo.project(points_left_m, "left"), stereo.project(points_left_m, "right")


def retriangulate(stereo: StereoCalibration, px_left: np.ndarray, px_right: np.ndarray):
    """Left-frame points (N, 3, m) of distorted pixel pairs under calibration ``stereo``."""
    return triangulate(stereo, stereo.undistort_rectify(px_left, "left"),
                       stereo.undistort_rectify(px_right, "right"))  # fmt: skip


def algebraic_circle(points_m: np.ndarray) -> np.ndarray:
    """(cx, cy, cz, r) of the circle through points (N, 3): least-squares plane, then the
    linear (Kasa) circle in it. Metres, the points' frame."""
    mean = points_m.mean(axis=0)
    d = points_m - mean
    _, _, Vt = np.linalg.svd(d, full_matrices=False)
    u, v = Vt[0], Vt[1]
    x, y = d @ u, d @ v
    A = np.column_stack([2 * x, 2 * y, np.ones_like(x)])
    (a, b, c), *_ = np.linalg.lstsq(A, x * x + y * y, rcond=None)
    r = float(np.sqrt(c + a * a + b * b))
    return np.array([*(mean + a * u + b * v), r])


def jacobian_covariance(
    stereo: StereoCalibration, points_left_m: np.ndarray, unc: CalibrationUncertainty
) -> np.ndarray:
    """4x4 covariance of (centre (left frame), radius) in m^2 from the calibration's
    uncertainties, by central differences of +-1 sigma per parameter (see module doc)."""
    if len(points_left_m) > MAX_JACOBIAN_POINTS:
        idx = np.linspace(0, len(points_left_m) - 1, MAX_JACOBIAN_POINTS).round().astype(int)
        points_left_m = np.asarray(points_left_m)[idx]
    px_l, px_r = pixel_pairs(stereo, points_left_m)
    sig = parameter_sigmas(unc)
    cols = []
    for i in np.flatnonzero(sig > 0):
        e = np.zeros(N_PARAMETERS)
        e[i] = sig[i]
        hi = algebraic_circle(retriangulate(perturbed(stereo, e), px_l, px_r))
        lo = algebraic_circle(retriangulate(perturbed(stereo, -e), px_l, px_r))
        cols.append(0.5 * (hi - lo))  # sensitivity x sigma: one parameter's contribution
    if not cols:
        return np.zeros((4, 4))
    J = np.column_stack(cols)
    return J @ J.T


def monte_carlo_covariance(
    stereo: StereoCalibration,
    points_left_m: np.ndarray,
    unc: CalibrationUncertainty,
    n: int = 200,
    seed: int = 0,
) -> np.ndarray:
    """The same covariance by Monte Carlo: ``n`` calibrations drawn from independent normal
    parameters, each re-triangulating the pairs and refitted with :func:`measure.fit_circle_3d`
    (the measurement's own fit, without rejection)."""
    rng = np.random.default_rng(seed)
    px_l, px_r = pixel_pairs(stereo, points_left_m)
    sig = parameter_sigmas(unc)
    out = []
    for _ in range(n):
        pts = retriangulate(perturbed(stereo, rng.normal(0.0, 1.0, N_PARAMETERS) * sig),
                            px_l, px_r)  # fmt: skip
        c = fit_circle_3d(pts, robust=False)
        out.append([*c.center, c.radius])
    return np.cov(np.asarray(out).T)
