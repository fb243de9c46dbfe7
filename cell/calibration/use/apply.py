"""The calibrated kinematics: what a run takes from ``cellcal.json``.

:class:`CalibratedKinematics` gives the calibrated D-H table (the thermal model identifies on
top of it), ``T_base_tool0(q)``, the hand-eye ``T_tool0_camera``, the camera's pose
``T_base_camera(q)`` and the covariance, in ``base_link``, of a point fixed in the camera
frame (a hole's centre measured by the head) that the calibration's uncertainty causes:
first-order propagation through the hand-eye and the D-H terms with their joint covariance.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from cell.calibration.estimate.result import CellCalibration
from robots.calibration import calibrated_table, dh_error_twists, fk_with_errors, term_names
from robots.dh import DHTable, fk_dh
from robots.transforms import skew

Array = NDArray[np.float64]


class CalibratedKinematics:
    """Forward kinematics and hand-eye of a calibration.

    ``nominal``: the arm's table, needed when the calibration has no D-H terms (offline data
    with flange poses); ignored otherwise (the file's nominal table is used).
    """

    def __init__(self, cal: CellCalibration, nominal: DHTable | None = None) -> None:
        self.calibration = cal
        base = cal.nominal_dh if cal.nominal_dh is not None else nominal
        if base is None:
            raise ValueError("the calibration has no D-H table: give the arm's nominal table")
        self.nominal = base
        self.delta = cal.delta
        self.dh_table: DHTable = calibrated_table(base, self.delta)
        self.T_tool0_camera: Array = cal.T_tool0_camera.T.copy()
        self._factor: Array | None = None

    def T_base_tool0(self, q: ArrayLike) -> Array:
        """``T_base_tool0`` (..., 4, 4) of joints ``q`` (rad, (6,) or (N, 6)), calibrated."""
        return fk_dh(self.dh_table, q)

    def T_base_camera(self, q: ArrayLike) -> Array:
        """The left camera's pose in ``base_link`` (..., 4, 4) at joints ``q``."""
        return self.T_base_tool0(q) @ self.T_tool0_camera

    def point_covariance(self, q: ArrayLike, p_camera_m: ArrayLike, frame: str = "base") -> Array:
        """Covariance (3, 3) (m^2) of the point ``p_camera_m`` (3,) fixed in the left camera's
        frame, at joints ``q`` (6,): ``J C J^T`` over the free hand-eye and D-H terms
        (``J``: :meth:`point_jacobian`).

        ``frame="base"``: in ``base_link`` (the target's pose and the stereo extrinsics do not
        move such a point; but ``base_link`` itself is only known through the target, so this
        holds the gauge's share: the part of the D-H and hand-eye uncertainty that the
        target's pose absorbs). ``frame="target"``: relative to the calibration target, with
        the target's pose and its correlations included: the uncertainty of a point measured
        in a cell whose frame is tied to the target."""
        J = self.point_jacobian(q, p_camera_m, frame)
        return J @ self.calibration.covariance @ J.T

    def point_jacobian(self, q: ArrayLike, p_camera_m: ArrayLike, frame: str = "base") -> Array:
        """``J`` (3, p): the point's motion (m, in ``base_link`` axes, or the target's for
        ``frame="target"``) per unit change of each free parameter (``parameter_names``
        order; zero columns for the stereo extrinsics, which do not move a point of the left
        camera, and for the target's pose with ``frame="base"``)."""
        if frame not in ("base", "target"):
            raise ValueError(f"frame must be 'base' or 'target', got {frame!r}")
        cal = self.calibration
        q = np.asarray(q, float).reshape(6)
        p_c = np.asarray(p_camera_m, float).reshape(3)
        T = fk_with_errors(self.nominal, self.delta, q)
        R_bt = T[:3, :3]
        X = self.T_tool0_camera
        p_b = (T @ X @ np.append(p_c, 1.0))[:3]
        cols: dict[str, Array] = {}
        for k, axis in enumerate(("x_m", "y_m", "z_m")):
            cols[f"T_tool0_camera.{axis}"] = R_bt[:, k]
        rot = -R_bt @ skew(X[:3, :3] @ p_c)
        for k, axis in enumerate(("rx_rad", "ry_rad", "rz_rad")):
            cols[f"T_tool0_camera.{axis}"] = rot[:, k]
        if cal.dh_terms:
            tw = dh_error_twists(self.nominal, self.delta, q)
            for k, n in enumerate(term_names()):
                cols[f"dh.{n}"] = tw[k, :3] + np.cross(tw[k, 3:], p_b)
        if frame == "target":
            R_Y, t_Y = cal.T_base_target.T[:3, :3], cal.T_base_target.T[:3, 3]
            cols = {k: R_Y.T @ v for k, v in cols.items()}
            for k, axis in enumerate(("x_m", "y_m", "z_m")):
                cols[f"T_base_target.{axis}"] = -R_Y.T[:, k]
            rot_t = R_Y.T @ skew(p_b - t_Y)
            for k, axis in enumerate(("rx_rad", "ry_rad", "rz_rad")):
                cols[f"T_base_target.{axis}"] = rot_t[:, k]
        J = np.zeros((3, len(cal.parameter_names)))
        for i, name in enumerate(cal.parameter_names):
            if name in cols:
                J[:, i] = cols[name]
        return J

    def covariance_factor(self) -> Array:
        """``L`` (p, p) with ``L L^T`` = the parameters' covariance (a symmetric square root;
        negative rounding eigenvalues clipped): ``J L z`` with ``z ~ N(0, I)`` draws a point's
        error, one ``z`` shared by every point of a run."""
        if self._factor is None:
            C = self.calibration.covariance
            w, v = np.linalg.eigh(0.5 * (C + C.T))
            self._factor = v * np.sqrt(np.clip(w, 0.0, None))
        return self._factor
