"""The simulated controller served over a pseudo-terminal pair or a local TCP socket.

A pty carries the bytes through the kernel's real serial (tty) stack: the host opens the slave
device path with pyserial exactly as it would open ``/dev/ttyS0``. A socket is reached with
``socket://127.0.0.1:PORT``. Frame faults from a :class:`cell.sim.faults.FaultPlan` are applied
here, at the wire.
"""

from __future__ import annotations

import heapq
import logging
import os
import select
import socket
import threading
import time
import tty

import numpy as np

from cell.link import frame as fr
from cell.link import messages as m
from cell.sim.controller import SimController
from cell.sim.faults import FaultPlan, Outage

log = logging.getLogger(__name__)


class SimServer:
    """Serves one :class:`SimController` in a background thread. ``url`` is what the host opens.

    ``transport`` is ``"pty"`` or ``"socket"``. Use :meth:`start` / :meth:`close` or ``with``.
    """

    def __init__(
        self, controller: SimController, faults: FaultPlan | None = None, transport: str = "pty"
    ) -> None:
        if transport not in ("pty", "socket"):
            raise ValueError(f"transport {transport!r} must be 'pty' or 'socket'")
        self.controller = controller
        self.faults = faults or FaultPlan()
        self.transport = transport
        self._rng = np.random.default_rng(self.faults.seed)
        self._decoder = fr.FrameDecoder()
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self._out: list[tuple[float, int, bytes]] = []
        self._n_out = 0
        self.requests = 0
        self.dropped = 0
        self.corrupted = 0
        self.disconnects = 0
        self._outage = Outage(self.faults)
        self._listener: socket.socket | None = None
        self._conn: socket.socket | None = None
        self._closed = False
        if transport == "pty":
            self._master, self._slave = os.openpty()
            try:
                tty.setraw(self._slave)
                os.set_blocking(self._master, False)
                self.url = os.ttyname(self._slave)
            except BaseException:
                os.close(self._master)
                os.close(self._slave)
                raise
        else:
            self._listener = socket.create_server(("127.0.0.1", 0))
            self._listener.setblocking(False)
            self.url = f"socket://127.0.0.1:{self._listener.getsockname()[1]}"

    def start(self) -> SimServer:
        """Start serving in a daemon thread (once)."""
        if self._thread is not None:
            return self
        self._thread = threading.Thread(target=self._run, name="holecell-sim", daemon=True)
        self._thread.start()
        return self

    def close(self) -> None:
        """Stop serving and release the pty or socket; closing again does nothing."""
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout=2.0)
        if self._closed:
            return
        self._closed = True
        if self.transport == "pty":
            for fd in (self._master, self._slave):
                os.close(fd)
        else:
            for s in (self._conn, self._listener):
                if s is not None:
                    s.close()

    def __enter__(self) -> SimServer:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.close()

    def serve_forever(self) -> None:
        """Serve in the calling thread until interrupted."""
        self._run()

    # --- the loop ---------------------------------------------------------------------------
    def _run(self) -> None:
        while not self._stop.is_set():
            fd = self._fd()
            timeout = 0.002
            if fd is None:
                self._accept()
                time.sleep(timeout)
            else:
                ready, _, _ = select.select([fd], [], [], timeout)
                if ready:
                    self._receive(fd)
            self.controller.update()
            self._flush()

    def _fd(self) -> int | None:
        if self.transport == "pty":
            return self._master
        return self._conn.fileno() if self._conn is not None else None

    def _accept(self) -> None:
        if self._outage.timed_out() or self._listener is None:
            return
        try:
            conn, _ = self._listener.accept()
        except BlockingIOError:
            return
        conn.setblocking(False)
        conn.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        self._outage.reconnected()
        self._conn = conn

    def _read(self, fd: int) -> bytes:
        try:
            if self.transport == "pty":
                return os.read(fd, 4096)
            data = self._conn.recv(4096)
        except (BlockingIOError, InterruptedError):
            return b""
        except OSError:
            data = b""
        if not data and self.transport == "socket":
            self._drop_connection()
        return data

    def _drop_connection(self) -> None:
        if self._conn is not None:
            self._conn.close()
            self._conn = None
        self._decoder = fr.FrameDecoder()

    def _receive(self, fd: int) -> None:
        data = self._read(fd)
        if not data or self._outage.swallow(data):
            return
        if self._rng.random() < self.faults.drop:
            self.dropped += 1
            return
        if self._rng.random() < self.faults.corrupt:
            data = _flip_bit(data, self._rng)
            self.corrupted += 1
        corrupt_before = self._decoder.corrupt
        frames = self._decoder.feed(data)
        if self._decoder.corrupt > corrupt_before:
            self._send(fr.encode(m.Msg.NAK, 0xFF, bytes([m.Nak.CRC]) + b"bad CRC"))
        for f in frames:
            self.requests += 1
            if self.requests == self.faults.disconnect_after:
                self._disconnect()
                return
            self._send(self.controller.handle(f))

    def _disconnect(self) -> None:
        log.info("simulated disconnect for %.2f s", self.faults.disconnect_s)
        self.disconnects += 1
        self._outage.start()
        self._out.clear()
        if self.transport == "socket":
            self._drop_connection()

    def _send(self, wire: bytes) -> None:
        if self._rng.random() < self.faults.drop:
            self.dropped += 1
            return
        if self._rng.random() < self.faults.corrupt:
            wire = _flip_bit(wire, self._rng)
            self.corrupted += 1
        due = time.monotonic()
        if self._rng.random() < self.faults.delay:
            due += self.faults.delay_s
        self._n_out += 1
        heapq.heappush(self._out, (due, self._n_out, wire))

    def _flush(self) -> None:
        now = time.monotonic()
        while self._out and self._out[0][0] <= now:
            _, _, wire = heapq.heappop(self._out)
            self._write(wire)

    def _write(self, wire: bytes) -> None:
        try:
            if self.transport == "pty":
                os.write(self._master, wire)
            elif self._conn is not None:
                self._conn.sendall(wire)
        except OSError as exc:
            log.info("write failed: %s", exc)
            if self.transport == "socket":
                self._drop_connection()


def _flip_bit(data: bytes, rng: np.random.Generator) -> bytes:
    out = bytearray(data)
    out[int(rng.integers(len(out)))] ^= 1 << int(rng.integers(8))
    return bytes(out)
