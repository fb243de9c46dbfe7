"""The thermal model's prediction uncertainty at a pose: parameter covariance to TCP covariance.

Identification (:func:`robots.thermal.identify.identify`) gives the covariance ``Sigma`` of
the identified terms (``sigma^2 (J^T J)^-1``; ``k_link*`` in 1/K, ``c_joint*`` in rad/K),
stored with the model and in ``thermal.json``. A point rigidly attached to the TCP (the TCP
origin, or a hole centre at the standoff) is predicted at

    p_cell(q, T) = T_cell_base @ fk(q, T; theta) @ T_tool0_tcp @ p_tcp,

so its covariance is ``C = G Sigma G^T`` with ``G = d p_cell / d theta`` (3 x n_terms, m per
term unit). The lengths enter the forward kinematics linearly, so ``G`` is exact for the length
terms (central differences, 1 ppm/K steps); for offset terms it is the local linearisation.

``C`` is what the model's error at that pose and moment is expected to be *if the model's
structure is right* (each length growing linearly with its sensor's reading): it grows with the
temperature rise over the reference, and is zero at the reference temperatures.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Protocol

import numpy as np
from numpy.typing import ArrayLike

from robots.dh import DHTable
from robots.thermal.errors import ThermalSpecError
from robots.thermal.spec import (
    TERM_SCALE,
    Array,
    ThermalSpec,
    coefficient_vectors,
    fk_rows,
    term_kind_and_link,
)


class ThermalModel(Protocol):
    """What these functions read of an identified model (:class:`robots.thermal.ThermalModel`,
    which imports this module for its ``predict_covariance``)."""

    @property
    def table(self) -> DHTable: ...
    @property
    def spec(self) -> ThermalSpec: ...
    @property
    def coefficients(self) -> Mapping[str, float]: ...
    @property
    def std(self) -> Mapping[str, float]: ...
    @property
    def covariance(self) -> Array | None: ...
    @property
    def fit(self) -> Mapping[str, float]: ...
    @property
    def T_cell_base(self) -> Array: ...
    @property
    def T_tool0_tcp(self) -> Array: ...
    def fk(self, q: ArrayLike, temps_degC: ArrayLike) -> Array: ...


def covariance_matrix(model: ThermalModel) -> Array:
    """The terms' covariance (n, n) in SI units (1/K, rad/K squared), in the order of
    ``model.coefficients``: the stored full matrix, else the diagonal of ``model.std``
    (a term without a standard deviation gives NaN)."""
    names = tuple(model.coefficients)
    if model.covariance is not None:
        return np.asarray(model.covariance, float).reshape(len(names), len(names))
    std = np.array([float(model.std.get(n, np.nan)) for n in names])
    return np.diag(std**2)


def term_jacobian(
    model: ThermalModel,
    q: ArrayLike,
    temps_degC: ArrayLike,
    point_tcp_m: ArrayLike | None = None,
) -> Array:
    """``d p_base / d theta`` (..., 3, n_terms) of a TCP-fixed point, in the robot base frame.

    ``q`` (..., 6) rad, ``temps_degC`` (..., n_sensors), ``point_tcp_m`` (3,) in the TCP frame
    (default: the TCP origin). Columns in the order of ``model.coefficients``, in metres per
    term unit (1/K or rad/K).
    """
    names = tuple(model.coefficients)
    p_tcp = np.zeros(3) if point_tcp_m is None else np.asarray(point_tcp_m, float)
    if p_tcp.shape != (3,) or not np.all(np.isfinite(p_tcp)):
        raise ThermalSpecError("point_tcp_m", point_tcp_m, "expected three finite numbers (m)")
    q = model.table.joint_values(np.asarray(q, float))  # D-H joint variables
    temps = np.asarray(temps_degC, float)
    dT = model.spec.link_delta_K(temps)
    a0, d0, alpha, off0 = model.table.arrays()
    p_h = np.append(p_tcp, 1.0)
    T_tool0_tcp = np.asarray(model.T_tool0_tcp, float)
    base = dict(model.coefficients)
    cols = []
    for name in names:
        kind, _ = term_kind_and_link(name)
        h = TERM_SCALE[kind]
        pts = []
        for sign in (1.0, -1.0):
            k, c = coefficient_vectors({**base, name: base[name] + sign * h})
            scale = 1.0 + k * dT
            T = fk_rows(a0 * scale, d0 * scale, alpha, off0 + c * dT, q)
            pts.append((T @ T_tool0_tcp @ p_h)[..., :3])
        cols.append((pts[0] - pts[1]) / (2.0 * h))
    if not cols:
        return np.zeros((*np.broadcast_shapes(q.shape[:-1], dT.shape[:-1]), 3, 0))
    return np.stack(cols, axis=-1)


def prediction_covariance(
    model: ThermalModel,
    q: ArrayLike,
    temps_degC: ArrayLike,
    point_tcp_m: ArrayLike | None = None,
    T_cell_base: ArrayLike | None = None,
) -> Array:
    """Covariance (..., 3, 3) in m^2, cell frame, of the model's predicted position of a
    TCP-fixed point at joints ``q`` (..., 6) rad and sensor readings ``temps_degC`` (degC).

    ``point_tcp_m``: the point in the TCP frame (default the TCP origin; a hole measured at the
    standoff is at ``(0, 0, standoff_m)``). ``T_cell_base``: the base pose (default the model's
    own, from identification); only its rotation matters.
    """
    G = term_jacobian(model, q, temps_degC, point_tcp_m)
    S = covariance_matrix(model)
    C_base = G @ S @ np.swapaxes(G, -1, -2)
    T_cb = np.asarray(model.T_cell_base if T_cell_base is None else T_cell_base, float)
    R = T_cb[:3, :3]
    return R @ C_base @ R.T


def reading_covariance(
    model: ThermalModel,
    q: ArrayLike,
    temps_degC: ArrayLike,
    point_tcp_m: ArrayLike | None = None,
    T_cell_base: ArrayLike | None = None,
    u_reading_K: float | None = None,
) -> Array:
    """Covariance (3, 3) in m^2, cell frame, of the compensated position of a TCP-fixed point
    from the noise of the temperature readings: the prediction uses the stop's readings and the
    cold reference readings (one draw each, independent), so the variance is
    ``2 u^2 H H^T`` with ``H = d p / d T_sensor`` (m/K, exact: the model is linear in the
    readings). ``u_reading_K`` defaults to the identification's estimate
    ``model.fit["reading_noise_K"]`` (0 when the model has none: a zero matrix)."""
    u = float(model.fit.get("reading_noise_K", 0.0) if u_reading_K is None else u_reading_K)
    if not u > 0.0:
        return np.zeros((3, 3))
    p_h = np.append(np.zeros(3) if point_tcp_m is None else np.asarray(point_tcp_m, float), 1.0)
    temps = np.asarray(temps_degC, float)
    T_tt = np.asarray(model.T_tool0_tcp, float)
    cols = []
    for j in range(temps.shape[-1]):
        step = np.zeros_like(temps)
        step[j] = 0.5
        hi = (model.fk(q, temps + step) @ T_tt @ p_h)[:3]
        lo = (model.fk(q, temps - step) @ T_tt @ p_h)[:3]
        cols.append(hi - lo)  # per K (1 K step)
    H = np.column_stack(cols)
    R = np.asarray(model.T_cell_base if T_cell_base is None else T_cell_base, float)[:3, :3]
    return R @ (2.0 * u * u * H @ H.T) @ R.T
