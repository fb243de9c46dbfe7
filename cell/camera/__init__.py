"""The stereo head's cameras: the :class:`CameraBackend` interface, its :class:`StereoPair`,
the network backend and the cell's stereo calibration."""

from __future__ import annotations

from cell.camera.backend import CameraBackend, StereoPair
from cell.camera.errors import CameraError
from cell.camera.network import NetworkCamera, recv_exact
from cell.camera.stereo import cell_stereo

__all__ = [
    "CameraBackend",
    "CameraError",
    "NetworkCamera",
    "StereoPair",
    "cell_stereo",
    "recv_exact",
]
