"""How stereo pairs reach the cell computer: the :class:`CameraBackend` interface and the
:class:`StereoPair` it returns.

Images never travel over the robot's serial line. A real head is two GigE Vision or USB3
cameras triggered together; the simulated head renders pairs with :mod:`measure.synth` from the
simulator's truth, either in-process (:class:`cell.sim.camera.SimCamera`) or from a simulator
in another process over a local TCP socket (:class:`cell.camera.network.NetworkCamera`, served
by :mod:`cell.sim.camserver`).
"""

from __future__ import annotations

from contextlib import AbstractContextManager, nullcontext
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np

from measure import StereoCalibration


@dataclass(frozen=True)
class StereoPair:
    """One triggered capture: left and right images (distorted, as the cameras deliver them)."""

    left: np.ndarray
    right: np.ndarray


class CameraBackend(Protocol):
    """A stereo head the runner can trigger. ``stereo`` is its calibration."""

    stereo: StereoCalibration

    def capture(self) -> StereoPair:
        """Trigger both cameras together and return the pair."""
        ...

    def close(self) -> None:
        """Release the cameras."""
        ...


def computing(camera: Any) -> AbstractContextManager[Any]:
    """The block in which the cell computer works on a pair while the arm waits at its stop.
    A real head: nothing (the robot's time passes). The in-process simulated head
    (:meth:`cell.sim.camera.SimCamera.computing`) holds the simulation's clock there, as a
    computer that keeps up with its arm would: the simulated arm then warms by the same amount
    whatever the load of the machine running the simulation, and a seed gives the same figures."""
    hold = getattr(camera, "computing", None)
    return hold() if callable(hold) else nullcontext()
