"""The thermal model's prediction covariance of a measured point at one stop and moment.

The compensated pose ``T_cell_tcp(q, T; theta)`` depends on the identified terms ``theta``
(``k_link*`` 1/K, ``c_joint*`` rad/K). Their uncertainty moves every point the head measures:
``p_cell = T_cell_tcp(theta) p_tcp``. :func:`thermal_point_covariance` propagates it by central
differences of +-1 sigma per term (GUM's law of propagation).

When the model offers its own prediction covariance (``ThermalModel.predict_covariance``, from
the terms' full covariance kept with the model), that is used, plus the noise of the temperature
readings the prediction rests on (the stop's and the cold reference's, estimated by the
identification: :func:`robots.thermal.uncertainty.reading_covariance`). Otherwise (a model
without it) the terms' standard deviations (``ThermalModel.std``) are propagated here with the
terms taken as independent. :func:`thermal_point_covariance` is the one function that decides.
"""

from __future__ import annotations

import numpy as np

from robots.thermal.compensate import compensated_T_cell_tcp
from robots.thermal.model import ThermalModel
from robots.thermal.uncertainty import reading_covariance


def _with_coefficients(model: ThermalModel, coefficients: dict[str, float]) -> ThermalModel:
    from dataclasses import replace

    return replace(model, coefficients=coefficients)


def thermal_point_covariance(
    model: ThermalModel | None,
    T_cell_base: np.ndarray,
    T_tool0_tcp: np.ndarray,
    q_rad: np.ndarray,
    temps_c: np.ndarray,
    p_tcp_m: np.ndarray,
) -> np.ndarray:
    """3x3 covariance (m^2, cell frame) of a point seen at ``p_tcp_m`` (TCP frame) through the
    compensated kinematics at joints ``q_rad`` and readings ``temps_c`` (degC), from the
    model's term uncertainties. Zero without a model (the nominal kinematics have no identified
    terms; their error is then not covered: the budget notes it)."""
    if model is None:
        return np.zeros((3, 3))
    predict = getattr(model, "predict_covariance", None)
    if predict is not None:
        p = np.asarray(p_tcp_m, float)
        terms = np.asarray(predict(q_rad, temps_c, p, T_cell_base), float)
        return terms + reading_covariance(model, q_rad, temps_c, p, T_cell_base)
    if not model.std:
        return np.zeros((3, 3))
    p = np.append(np.asarray(p_tcp_m, float), 1.0)
    cols = []
    for name, sigma in model.std.items():
        if not sigma > 0 or name not in model.coefficients:
            continue
        pts = []
        for sign in (1.0, -1.0):
            c = dict(model.coefficients)
            c[name] = c[name] + sign * sigma
            T = compensated_T_cell_tcp(_with_coefficients(model, c), T_cell_base, T_tool0_tcp,
                                       q_rad, temps_c)  # fmt: skip
            pts.append((T @ p)[:3])
        cols.append(0.5 * (pts[0] - pts[1]))
    if not cols:
        return np.zeros((3, 3))
    J = np.column_stack(cols)
    return J @ J.T


def thermal_note(model: ThermalModel | None) -> str:
    """Where the thermal component's figures come from (for the budget)."""
    if model is None:
        return "no thermal model: nominal kinematics, their drift is not covered"
    if getattr(model, "predict_covariance", None) is not None:
        u = float(model.fit.get("reading_noise_K", 0.0))
        return (
            "the thermal model's prediction covariance (identified terms' full covariance)"
            f" and the readings' noise ({u:.3f} K per reading, stop and cold reference)"
        )
    return "identified terms' standard deviations (correlations not stored: taken as independent)"
