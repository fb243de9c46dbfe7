"""The simulated line behind the interpreted module's serial channel or socket: the faults of a
:class:`cell.sim.faults.FaultPlan` applied at the wire, as :class:`cell.sim.server.SimServer`
applies them to the Python controller (a received chunk or a sent frame dropped, a bit flipped,
an answer delayed, the link dead for ``disconnect_s`` after ``disconnect_after`` requests)."""

from __future__ import annotations

import heapq
import os
import select
import socket
import time

import numpy as np

from cell.link import frame as fr
from cell.sim.faults import FaultPlan, Outage


class WireFaults:
    """Faults and counters of one simulated line; ``cut`` is set at a disconnect (a socket is
    then closed by its owner)."""

    def __init__(self, plan: FaultPlan) -> None:
        self.plan = plan
        self._rng = np.random.default_rng(plan.seed)
        self._decoder = fr.FrameDecoder()
        self._out: list[tuple[float, int, bytes]] = []
        self._n_out = 0
        self.requests = self.dropped = self.corrupted = self.disconnects = 0
        self.outage = Outage(plan)
        self.cut = False

    def dead(self) -> bool:
        return self.outage.dead()

    def inbound(self, data: bytes) -> bytes:
        """What of a received chunk reaches the controller."""
        if not data or self.outage.swallow(data):
            return b""
        if self._rng.random() < self.plan.drop:
            self.dropped += 1
            return b""
        if self._rng.random() < self.plan.corrupt:
            data = _flip_bit(data, self._rng)
            self.corrupted += 1
        for _ in self._decoder.feed(data):
            self.requests += 1
            if self.requests == self.plan.disconnect_after:
                self.disconnects += 1
                self.outage.start()
                self._out.clear()
                self._decoder = fr.FrameDecoder()
                self.cut = True
                return b""
        return data

    def outbound(self, wire: bytes) -> None:
        """Schedule a frame the controller sends."""
        if self.dead():
            return
        if self._rng.random() < self.plan.drop:
            self.dropped += 1
            return
        if self._rng.random() < self.plan.corrupt:
            wire = _flip_bit(wire, self._rng)
            self.corrupted += 1
        due = time.monotonic()
        if self._rng.random() < self.plan.delay:
            due += self.plan.delay_s
        self._n_out += 1
        heapq.heappush(self._out, (due, self._n_out, wire))

    def due(self) -> list[bytes]:
        """The scheduled frames whose time has come."""
        now, out = time.monotonic(), []
        while self._out and self._out[0][0] <= now:
            out.append(heapq.heappop(self._out)[2])
        return out


class FaultyStream:
    """A byte stream (pty master or connected socket) seen through :class:`WireFaults`: reads
    in chunks as the kernel delivers them, faults per chunk, bytes handed out ``n`` at a time.
    ``read`` returns b"" on a timeout and None when the peer closed (or the line was cut)."""

    def __init__(self, wire: WireFaults, fd: int | None = None, sock: socket.socket | None = None):
        self.wire, self.fd, self.sock = wire, fd, sock
        self._buf = bytearray()

    def _raw_read(self) -> bytes | None:
        try:
            if self.sock is not None:
                return self.sock.recv(4096) or None
            return os.read(self.fd, 4096)
        except (BlockingIOError, InterruptedError):
            return b""
        except OSError:
            return None

    def _handle(self) -> int:
        return self.sock.fileno() if self.sock is not None else self.fd

    def flush(self) -> None:
        for wire in self.wire.due():
            self._raw_write(wire)

    def _raw_write(self, data: bytes) -> None:
        try:
            if self.sock is not None:
                self.sock.sendall(data)
            else:
                os.write(self.fd, data)
        except OSError:
            self.wire.cut = self.sock is not None

    def read(self, n: int, timeout_s: float) -> bytes | None:
        end = time.monotonic() + timeout_s
        while True:
            self.flush()
            if self.wire.cut and self.sock is not None:
                return None
            if self._buf:
                out = bytes(self._buf[:n])
                del self._buf[:n]
                return out
            left = end - time.monotonic()
            if left <= 0:
                return b""
            ready, _, _ = select.select([self._handle()], [], [], min(left, 0.002))
            if ready:
                data = self._raw_read()
                if data is None:
                    return None
                self._buf += self.wire.inbound(data)

    def write(self, data: bytes) -> None:
        self.wire.outbound(data)
        self.flush()

    def clear_input(self) -> None:
        self._buf.clear()
        while select.select([self._handle()], [], [], 0)[0]:
            if not self._raw_read():
                break


def _flip_bit(data: bytes, rng: np.random.Generator) -> bytes:
    out = bytearray(data)
    out[int(rng.integers(len(out)))] ^= 1 << int(rng.integers(8))
    return bytes(out)
