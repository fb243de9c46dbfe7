"""How stereo pairs reach the cell computer: the :class:`CameraBackend` interface.

Images never travel over the robot's serial line. A real head is two GigE Vision or USB3
cameras triggered together (a backend built on the vendor's SDK); the simulated head renders
pairs with :mod:`measure.synth` from the simulator's truth, either in-process
(:class:`cell.sim.camera.SimCamera`) or from a simulator in another process over a local TCP
socket (:class:`NetworkCamera`, served by :mod:`cell.sim.camserver`).
"""

from __future__ import annotations

import json
import socket
from dataclasses import dataclass
from typing import Protocol

import numpy as np

from cell.config import CellConfig
from cell.errors import CellError
from measure import StereoCalibration
from measure.synth import standard_stereo


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


def cell_stereo(cell: CellConfig) -> StereoCalibration:
    """The cell's stereo calibration file, or the standard head (:func:`measure.synth.
    standard_stereo`, the simulated head) when the cell names none."""
    path = cell.calibration_path()
    return StereoCalibration.load(path) if path is not None else standard_stereo()


class CameraError(CellError):
    """A capture failed (camera not reachable, bad image transfer)."""

    def __init__(self, source: str, reason: str) -> None:
        self.source = source
        self.reason = reason
        super().__init__(f"camera {source}: {reason}")


def recv_exact(sock: socket.socket, n: int, source: str) -> bytes:
    """Exactly ``n`` bytes from ``sock`` or :class:`CameraError`."""
    buf = bytearray()
    while len(buf) < n:
        chunk = sock.recv(min(1 << 20, n - len(buf)))
        if not chunk:
            raise CameraError(source, "connection closed during transfer")
        buf.extend(chunk)
    return bytes(buf)


class NetworkCamera:
    """A stereo head reached over TCP (``tcp://host:port``), e.g. the simulator's camera server.

    Request: the line ``CAPTURE\\n``. Answer: one JSON line ``{"shape": [h, w], "dtype": ...}``
    (or ``{"error": ...}``), then the left and the right image as raw row-major bytes.
    """

    def __init__(self, url: str, stereo: StereoCalibration, timeout_s: float = 30.0) -> None:
        if not url.startswith("tcp://"):
            raise CameraError(url, "expected tcp://HOST:PORT")
        host, _, port = url[len("tcp://") :].rpartition(":")
        self.url = url
        self.stereo = stereo
        try:
            self._sock = socket.create_connection((host, int(port)), timeout=timeout_s)
        except (OSError, ValueError) as exc:
            raise CameraError(url, f"cannot connect: {exc}") from exc

    def capture(self) -> StereoPair:
        """Trigger and receive one pair."""
        try:
            self._sock.sendall(b"CAPTURE\n")
            line = bytearray()
            while not line.endswith(b"\n"):
                line.extend(recv_exact(self._sock, 1, self.url))
            head = json.loads(line)
            if "error" in head:
                raise CameraError(self.url, head["error"])
            dtype, shape = np.dtype(head["dtype"]), tuple(head["shape"])
            n = int(np.prod(shape)) * dtype.itemsize
            left = np.frombuffer(recv_exact(self._sock, n, self.url), dtype).reshape(shape)
            right = np.frombuffer(recv_exact(self._sock, n, self.url), dtype).reshape(shape)
        except (OSError, ValueError, KeyError) as exc:
            raise CameraError(self.url, f"capture failed: {exc}") from exc
        return StereoPair(left, right)

    def close(self) -> None:
        """Close the connection."""
        self._sock.close()
