"""The simulated cell's true geometry, in one object: for the simulated head and for benchmarks.

Everything here is the truth (:class:`cell.sim.truth.CellTruth` applied to the cell file's
nominal geometry, plus the thermal drift): the runner must never use it. Lengths in m, times
in simulation seconds (the drift is evaluated at ``drift_offset_s + t_s``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from robots.dh import DHTable
from robots.thermal.drift import DriftTruth


@dataclass(frozen=True)
class TrueGeometry:
    """The true frames of a simulated cell.

    Attributes:
        table: the true D-H table (nominal plus the truth's errors), before thermal drift.
        drift: the thermal drift truth built on ``table``.
        drift_offset_s: warm-up already elapsed at simulation time 0 (s).
        T_cell_base: true pose of ``base_link`` in the cell.
        T_tool0_tcp: true pose of the head's view frame (TCP) on the flange.
        T_tcp_left: the left camera in the head frame (from the stereo head's extrinsics).
        T_cell_part: true pose of the part on its fixture.
        T_cell_target: true pose of the calibration target's board frame (None: no target).
    """

    table: DHTable
    drift: DriftTruth
    drift_offset_s: float
    T_cell_base: np.ndarray
    T_tool0_tcp: np.ndarray
    T_tcp_left: np.ndarray
    T_cell_part: np.ndarray
    T_cell_target: np.ndarray | None

    def T_base_tool0(self, q_rad: ArrayLike, t_s: float) -> np.ndarray:
        """True ``T_base_tool0`` at joints ``q_rad`` and simulation time ``t_s`` (D-H errors
        and thermal drift)."""
        return self.drift.T_base_tool0(np.asarray(q_rad, float), self.drift_offset_s + t_s)

    @property
    def T_tool0_camera_left(self) -> np.ndarray:
        """True pose of the left camera on the flange (the hand-eye transform)."""
        return self.T_tool0_tcp @ self.T_tcp_left

    def T_cell_tcp(self, q_rad: ArrayLike, t_s: float) -> np.ndarray:
        """True TCP pose in the cell (no repeatability scatter)."""
        return self.T_cell_base @ self.T_base_tool0(q_rad, t_s) @ self.T_tool0_tcp

    def T_cell_left(self, q_rad: ArrayLike, t_s: float) -> np.ndarray:
        """True left camera pose in the cell (no repeatability scatter)."""
        return self.T_cell_tcp(q_rad, t_s) @ self.T_tcp_left
