"""A stereo head reached over TCP (``tcp://host:port``): the simulator's camera server
(:mod:`cell.sim.camserver`) in another process."""

from __future__ import annotations

import json
import socket

import numpy as np

from cell.camera.backend import StereoPair
from cell.camera.errors import CameraError
from measure import StereoCalibration


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
