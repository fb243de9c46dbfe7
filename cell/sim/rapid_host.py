"""The simulated controller around the interpreted RAPID module: its serial channel (a pty
through :class:`cell.sim.rapid_wire.FaultyStream`), its sockets (real local TCP sockets, the
module's address and port mapped to 127.0.0.1 and a free port), its clocks, the temperature
inputs ``aiTempJ1``.. and the arm (:class:`cell.sim.rapid_arm.SimArm`).

Clocks: the controller clock that STATUS reports (``sim_clocks``, by variable name) runs in
simulation time; every other clock (the module's link watchdog) in wall time, as the host's
heartbeats do."""

from __future__ import annotations

import select
import socket
import threading
import time
from collections.abc import Callable

import numpy as np

from cell.rapid.interp.errors import RapidRunError
from cell.sim.rapid_arm import SimArm
from cell.sim.rapid_wire import FaultyStream, WireFaults
from cell.sim.world import SimClock


class ProgramHalt(Exception):  # noqa: N818 (control flow)
    """The host stops the program: ``reason`` "estop" (then restart) or "shutdown"."""

    def __init__(self, reason: str) -> None:
        self.reason = reason
        super().__init__(reason)


class SimHost:
    """The host of :class:`cell.sim.rapid_controller.RapidController`."""

    def __init__(
        self,
        clock: SimClock,
        temperatures: Callable[[float], np.ndarray],
        n_sensors: int,
        q0_deg: np.ndarray,
        wire: WireFaults,
        serial_fd: int | None,
        sim_clocks: tuple[str, ...] = ("hcclock",),
    ) -> None:
        self.clock, self.temperatures, self.wire = clock, temperatures, wire
        self.signals = {f"aiTempJ{i}": i - 1 for i in range(1, n_sensors + 1)}
        self.sim_clocks = sim_clocks
        self.arm = SimArm(clock, q0_deg, self._check)
        self._serial = None if serial_fd is None else FaultyStream(wire, fd=serial_fd)
        self.halt_request: str | None = None
        self.estop_check: Callable[[], bool] = lambda: False
        self.bound = threading.Event()
        self.bound_port = 0
        self._wall0 = time.monotonic()

    # --- program control --------------------------------------------------------------------
    def _check(self) -> None:
        if self.halt_request is not None:
            raise ProgramHalt(self.halt_request)
        if self.estop_check():
            raise ProgramHalt("estop")

    def poll(self) -> None:
        self._check()

    # --- devices ----------------------------------------------------------------------------
    def open_device(self, name: str):
        if name.lower() != "com1:" or self._serial is None:
            raise RapidRunError("ERR_FILEOPEN", f"no device {name!r} on this controller")
        return _Serial(self._serial)

    def socket(self):
        return SimSocket(self)

    # --- time, signals, arm -----------------------------------------------------------------
    def now_s(self, clock: str) -> float:
        if clock in self.sim_clocks:
            return self.clock.now()
        return time.monotonic() - self._wall0

    def wait(self, seconds: float) -> None:
        end = time.monotonic() + self.clock.wall_for(seconds)
        while time.monotonic() < end:
            self._check()
            time.sleep(min(0.002, max(end - time.monotonic(), 0.0)))

    def has_signal(self, name: str) -> bool:
        return name in self.signals

    def analog_input(self, name: str) -> float:
        return float(self.temperatures(self.clock.now())[self.signals[name]])

    def joints_deg(self) -> list[float]:
        return [float(v) for v in self.arm.position()]

    def move_abs_j(self, q_deg, time_s, fine, conc) -> None:
        self.arm.move(q_deg, time_s, fine, conc)

    def stop_move(self) -> None:
        self.arm.halt()

    def clear_path(self) -> None:
        self.arm.halt()

    def start_move(self) -> None:
        """Nothing is queued after ClearPath: motion resumes with the next move."""


class _Serial:
    """The opened channel "com1:" (Close forgets it, the pty stays)."""

    def __init__(self, stream: FaultyStream) -> None:
        self.stream = stream

    def read(self, n: int, timeout_s: float) -> bytes:
        return self.stream.read(n, timeout_s) or b""

    def write(self, data: bytes) -> None:
        self.stream.write(data)

    def clear_input(self) -> None:
        self.stream.clear_input()

    def close(self) -> None:
        self.stream.flush()


class SimSocket:
    """A ``socketdev``: a real TCP socket on 127.0.0.1 (the server's port chosen free and
    published as ``host.bound_port``); a connection sees the wire's faults."""

    def __init__(self, host: SimHost, conn: socket.socket | None = None) -> None:
        self.host, self.sock = host, conn
        self.stream = None if conn is None else FaultyStream(host.wire, sock=conn)
        self.state = "SOCKET_CONNECTED" if conn is not None else "SOCKET_CREATED"

    def bind(self, address: str, port: int) -> None:
        if self.sock is not None:
            raise RapidRunError("ERR_SOCK_ADDR_INUSE", "socket already bound")
        if not 0 < port < 65536:
            raise RapidRunError("ERR_ARGVALERR", f"port {port}")
        s = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        # a module set for this machine's loopback binds its port; any other address (the
        # controller's own) is simulated on a free loopback port
        s.bind(("127.0.0.1", port if address == "127.0.0.1" else 0))
        self.sock, self.state = s, "SOCKET_BOUND"
        self.host.bound_port = s.getsockname()[1]

    def listen(self) -> None:
        if self.state != "SOCKET_BOUND":
            raise RapidRunError("ERR_SOCK_CLOSED", "SocketListen before SocketBind")
        self.sock.listen(1)
        self.state = "SOCKET_LISTENING"
        self.host.bound.set()

    def accept(self, timeout_s: float) -> SimSocket:
        if self.state != "SOCKET_LISTENING":
            raise RapidRunError("ERR_SOCK_CLOSED", "SocketAccept on a socket not listening")
        end = time.monotonic() + timeout_s
        while True:
            self.host.poll()
            left = end - time.monotonic()
            wait_s = max(0.0, min(left, 0.002))
            alive = not self.host.wire.outage.timed_out()
            if alive and select.select([self.sock], [], [], wait_s)[0]:
                conn, _ = self.sock.accept()
                conn.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
                conn.setblocking(False)
                self.host.wire.cut = False
                self.host.wire.outage.reconnected()
                return SimSocket(self.host, conn)
            if left <= 0:
                raise RapidRunError("ERR_SOCK_TIMEOUT", f"no connection within {timeout_s} s")
            if self.host.wire.outage.timed_out():
                time.sleep(min(left, 0.002))

    def connect(self, address: str, port: int, timeout_s: float) -> None:
        raise RapidRunError("ERR_SOCK_NET_UNREACH", "the simulated controller is the server")

    def _live(self) -> FaultyStream:
        if self.stream is None or self.state != "SOCKET_CONNECTED":
            raise RapidRunError("ERR_SOCK_CLOSED", "socket not connected")
        return self.stream

    def send(self, data: bytes) -> None:
        s = self._live()
        if self.host.wire.cut:
            self._closed()
        s.write(data)

    def receive(self, n: int, exact: bool, timeout_s: float) -> bytes:
        s, out = self._live(), b""
        end = time.monotonic() + timeout_s
        while True:
            got = s.read(n - len(out), max(0.0, end - time.monotonic()))
            if got is None:
                self._closed()
            out += got
            if out and (not exact or len(out) == n):
                return out
            if time.monotonic() >= end:
                raise RapidRunError("ERR_SOCK_TIMEOUT", f"{len(out)} of {n} bytes in {timeout_s} s")

    def _closed(self):
        self.close()
        raise RapidRunError("ERR_SOCK_CLOSED", "the peer closed the connection")

    def close(self) -> None:
        if self.sock is not None:
            self.sock.close()
        self.state = "SOCKET_CLOSED"

    def status(self) -> str:
        return self.state
