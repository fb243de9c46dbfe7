"""An independent warm-up truth for the thermal benchmark, written apart from robots.thermal.drift.

Nothing here calls the project's drift generator, its D-H forward kinematics or its observation
simulator:

- **Temperatures** come from a lumped thermal network per joint integrated by SciPy
  (``solve_ivp``, LSODA): a motor node heated by a duty cycle that varies over the warm-up
  (``Q_i (1 + 0.3 sin(2 pi t / 1800 s))``) and a structure node coupled to the motor and to the
  hall. The controller's sensor ``j<i>`` reads the structure node of joint ``i`` (with noise).
  The link's own temperature is that node (``lag_s=None``: each sensor on its link) or a
  first-order lag of it (``dT_link/dt = (T_sensor - T_link) / lag_s``: the link lags its sensor).
- **Kinematics** are Pinocchio's forward kinematics of the arm's URDF, whose joint placements
  (the link lengths) grow linearly with their link's temperature rise: link 1 the base height
  (``joint_1``) and shoulder offset (``joint_2``), link 2 the upper arm (``joint_3``), link 3 the
  elbow offset (``joint_4``), link 4 the forearm (``joint_5``), link 6 the wrist-to-flange length
  (``joint_6``). The same "linear-length" structure as the model, in another parametrisation and
  another code path.
- **Observations** of a target are its position in the true TCP frame plus Gaussian noise.

SI units: s, K (rises), degC (readings), m.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike, NDArray
from scipy.integrate import solve_ivp

Array = NDArray[np.float64]

#: URDF joints whose placement carries each D-H link's lengths (index = link - 1)
LINK_PLACEMENTS: tuple[tuple[int, ...], ...] = ((1, 2), (3,), (4,), (5,), (), (6,))


@dataclass(frozen=True)
class NetworkSettings:
    """The thermal network and the true expansion of the links.

    Attributes:
        expansion_per_K: true linear expansion of each link (1/K), shape (6,).
        heat_K: steady motor-to-structure drive of each joint (K of structure rise at steady state).
        tau_motor_s: time constant of each motor node (s).
        tau_structure_s: time constant of each structure node (s).
        lag_s: first-order lag of each link behind its sensor (s); None: the sensor is the link.
        ambient_degC: hall and cold-arm temperature (degC).
        sensor_noise_K: noise of each reading (K).
    """

    expansion_per_K: tuple[float, ...] = (10.5e-6, 22.5e-6, 24.0e-6, 23.0e-6, 12.0e-6, 12.5e-6)  # noqa: N815 (unit suffix)
    heat_K: tuple[float, ...] = (9.0, 17.0, 15.0, 16.0, 13.0, 11.0)  # noqa: N815 (unit suffix)
    tau_motor_s: tuple[float, ...] = (900.0, 700.0, 600.0, 500.0, 450.0, 400.0)
    tau_structure_s: tuple[float, ...] = (3300.0, 2600.0, 2100.0, 1900.0, 1600.0, 1500.0)
    lag_s: tuple[float, ...] | None = None
    ambient_degC: float = 20.5  # noqa: N815 (unit suffix)
    sensor_noise_K: float = 0.05  # noqa: N815 (unit suffix)


class IndependentTruth:
    """The true thermal state and kinematics of a warming arm (see the module docstring)."""

    def __init__(
        self,
        arm_model: pin.Model,
        settings: NetworkSettings,
        duration_s: float = 7200.0,
        seed: int = 0,
    ) -> None:
        self.model = arm_model
        self.settings = settings
        self.rng = np.random.default_rng(seed)
        self.tool0 = arm_model.getFrameId("tool0")
        self.nominal = [arm_model.jointPlacements[j].copy() for j in range(arm_model.njoints)]
        self.truth_model = arm_model.copy()
        self.data = self.truth_model.createData()
        s = settings
        n = 6
        lag = s.lag_s

        def rhs(t: float, y: Array) -> Array:
            motor, struct, link = y[:n], y[n : 2 * n], y[2 * n :]
            duty = 1.0 + 0.3 * np.sin(2 * np.pi * t / 1800.0)
            q_in = np.asarray(s.heat_K) * duty
            d_motor = (q_in - (motor - struct)) / np.asarray(s.tau_motor_s)
            d_struct = ((motor - struct) - struct) / np.asarray(s.tau_structure_s)
            d_link = np.zeros(n) if lag is None else (struct - link) / np.asarray(lag)
            return np.concatenate([d_motor, d_struct, d_link])

        self.solution = solve_ivp(
            rhs, (0.0, duration_s), np.zeros(3 * n), method="LSODA", dense_output=True,
            max_step=60.0, rtol=1e-8, atol=1e-10,
        )  # fmt: skip

    def _state(self, t_s: ArrayLike) -> Array:
        t = np.clip(np.atleast_1d(np.asarray(t_s, float)), 0.0, self.solution.t[-1])
        return self.solution.sol(t).T  # (N, 18)

    def sensor_readings(self, t_s: ArrayLike, noisy: bool = True) -> Array:
        """Readings (degC) of the six joint sensors at times ``t_s`` (N,), shape (N, 6)."""
        y = self._state(t_s)[:, 6:12] + self.settings.ambient_degC
        if noisy and self.settings.sensor_noise_K > 0:
            y = y + self.rng.normal(0.0, self.settings.sensor_noise_K, y.shape)
        return y

    def link_rise_K(self, t_s: ArrayLike) -> Array:
        """True temperature rise of each link (K), shape (N, 6)."""
        y = self._state(t_s)
        return y[:, 6:12] if self.settings.lag_s is None else y[:, 12:18]

    def T_base_tool0(self, q: ArrayLike, t_s: ArrayLike) -> Array:
        """True ``T_base_tool0`` (N, 4, 4) by Pinocchio on the lengthened URDF."""
        Q = np.atleast_2d(np.asarray(q, float))
        t = np.broadcast_to(np.asarray(t_s, float), (len(Q),))
        rises = self.link_rise_K(t)
        k = np.asarray(self.settings.expansion_per_K)
        out = np.empty((len(Q), 4, 4))
        for r, (qr, rise) in enumerate(zip(Q, rises, strict=True)):
            for link, joints in enumerate(LINK_PLACEMENTS):
                for j in joints:
                    placement = self.nominal[j].copy()
                    placement.translation = placement.translation * (1.0 + k[link] * rise[link])
                    self.truth_model.jointPlacements[j] = placement
            pin.framesForwardKinematics(self.truth_model, self.data, qr)
            out[r] = self.data.oMf[self.tool0].homogeneous
        return out

    def observe(
        self,
        plan: Sequence[tuple[str, ArrayLike]],
        times_s: ArrayLike,
        targets_base_m: dict[str, Array],
        T_tool0_tcp: Array,
        noise_m: float,
    ) -> tuple[Array, list[str], Array, Array, Array]:
        """Every view of ``plan`` at every time: ``(t (N,), ids, q (N, 6), readings (N, 6),
        target in the TCP frame (N, 3) with noise)``."""
        times = np.asarray(times_s, float)
        t = np.repeat(times, len(plan))
        ids = [tid for _ in times for tid, _ in plan]
        q = np.array([np.asarray(qq, float) for _ in times for _, qq in plan])
        T = self.T_base_tool0(q, t) @ T_tool0_tcp
        p = np.array([targets_base_m[i] for i in ids])
        p_tcp = np.einsum("nji,nj->ni", T[:, :3, :3], p - T[:, :3, 3])
        p_tcp = p_tcp + self.rng.normal(0.0, noise_m, p_tcp.shape)
        return t, ids, q, self.sensor_readings(t), p_tcp
