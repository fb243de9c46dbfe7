"""The simulated head served over TCP, for a runner in another process (:class:`NetworkCamera`).

One client at a time; each ``CAPTURE`` line is answered by a JSON header line and the two raw
images (see :class:`cell.camera.NetworkCamera`).
"""

from __future__ import annotations

import json
import logging
import socket
import threading

from cell.camera import CameraError
from cell.sim.camera import SimCamera

log = logging.getLogger(__name__)


#: longest wait for one stereo pair to be taken up by the client (s)
SEND_TIMEOUT_S = 30.0


class CameraServer:
    """Serves a :class:`SimCamera` on ``tcp://127.0.0.1:PORT`` (``url``) in a daemon thread."""

    def __init__(self, camera: SimCamera, port: int = 0) -> None:
        self.camera = camera
        self._listener = socket.create_server(("127.0.0.1", port))
        self._listener.settimeout(0.2)
        self.url = f"tcp://127.0.0.1:{self._listener.getsockname()[1]}"
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name="holecell-camera", daemon=True)

    def start(self) -> CameraServer:
        """Start serving."""
        self._thread.start()
        return self

    def __enter__(self) -> CameraServer:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def close(self) -> None:
        """Stop serving."""
        self._stop.set()
        self._thread.join(timeout=2.0)
        self._listener.close()

    def _run(self) -> None:
        while not self._stop.is_set():
            try:
                conn, _ = self._listener.accept()
            except TimeoutError:
                continue
            except OSError:
                return
            with conn:
                self._serve(conn)

    def _serve(self, conn: socket.socket) -> None:
        conn.settimeout(0.2)
        buf = b""
        while not self._stop.is_set():
            try:
                chunk = conn.recv(64)
            except TimeoutError:
                continue
            except OSError:
                return
            if not chunk:
                return
            buf += chunk
            while b"\n" in buf:
                line, buf = buf.split(b"\n", 1)
                if line.strip() == b"CAPTURE":
                    # the short timeout is for noticing a stop between requests; a pair of
                    # megabytes to a busy client may take longer than that to send
                    conn.settimeout(SEND_TIMEOUT_S)
                    try:
                        self._answer(conn)
                    except OSError as exc:  # the client went away mid-transfer
                        log.info("camera client lost: %s", exc)
                        return
                    conn.settimeout(0.2)

    def _answer(self, conn: socket.socket) -> None:
        try:
            pair = self.camera.capture()
        except (CameraError, ValueError) as exc:
            conn.sendall(json.dumps({"error": str(exc)}).encode() + b"\n")
            return
        head = {"shape": list(pair.left.shape), "dtype": pair.left.dtype.str}
        conn.sendall(json.dumps(head).encode() + b"\n")
        conn.sendall(pair.left.tobytes())
        conn.sendall(pair.right.tobytes())
