"""Kinematic calibration of an arm: D-H error parameters, their forward kinematics and Jacobian.

The generic, camera-free part of the cell calibration (:mod:`cell.calibration` adds the cameras,
the target and the adjustment): :mod:`robots.calibration.dh_errors` holds the error vector
``delta`` (24 numbers, per joint ``a_m, d_m, alpha_rad, theta_rad``) added to a nominal
:class:`robots.dh.DHTable`, the forward kinematics with it and the spatial twists of every
term; :mod:`robots.calibration.redundancy` names the terms that a pose of the base (or of
anything fixed in it) and a pose fixed in ``tool0`` absorb.
"""

from robots.calibration.dh_errors import (
    DH_TERMS,
    N_DH_TERMS,
    calibrated_table,
    dh_error_twists,
    fk_with_errors,
    term_names,
)
from robots.calibration.redundancy import structural_redundancies

__all__ = [
    "DH_TERMS",
    "N_DH_TERMS",
    "calibrated_table",
    "dh_error_twists",
    "fk_with_errors",
    "structural_redundancies",
    "term_names",
]
