"""The shipped RAPID module (``cell/rapid/HolecellLink.mod``) run by the interpreter
(:mod:`cell.rapid.interp`) as the simulated controller: the same simulated world behind its
``MoveAbsJ``, ``CJointT`` and ``AInput``, served on a pty (``HC_TRANSPORT "serial"``) or a local
TCP socket (``"socket"``: the module's own SocketCreate/Bind/Listen/Accept).

It stands where :class:`cell.sim.server.SimServer` and :class:`cell.sim.controller.SimController`
stand (``url``, ``start``/``close``, the fault counters; ``q_rad``, ``s``, ``estop_at_stop``).
The integrator's settings are the module's CONSTs, set at load: the robot model, the link
timeout, the number of temperature inputs, the transport. An emergency stop (``estop_at_stop``:
on arrival at that stop) stops the program, runs the event routine ``hcOnEstop`` and starts
``hcMain`` again, module data kept."""

from __future__ import annotations

import logging
import os
import threading
import tty
from collections.abc import Callable
from pathlib import Path

import numpy as np

import cell
from cell.link import messages as m
from cell.rapid.interp import Program, RapidStopped
from cell.sim.faults import FaultPlan
from cell.sim.rapid_host import ProgramHalt, SimHost
from cell.sim.rapid_wire import WireFaults
from cell.sim.world import SimClock

log = logging.getLogger(__name__)
MODULE = Path(cell.__file__).parent / "rapid" / "HolecellLink.mod"


class RapidState:
    """A read-out of the module's data in the shape of ``SimControllerState``."""

    def __init__(self, ctrl: RapidController) -> None:
        self._c = ctrl

    def _num(self, name: str) -> int:
        return int(self._c.program.global_value(name))

    @property
    def state(self) -> m.State:
        return m.State(self._num("hcState"))

    @property
    def fault(self) -> m.Fault:
        return m.Fault(self._num("hcFault"))

    @property
    def at_stop(self) -> int:
        return self._num("hcAtStop")

    @property
    def target_stop(self) -> int:
        return self._num("hcTargetStop")

    @property
    def pos(self) -> float:
        return float(self._num("hcPos") - 1)

    @property
    def q_udeg(self) -> np.ndarray:
        return self._c.host.arm.position() * 1e6

    @q_udeg.setter
    def q_udeg(self, value: np.ndarray) -> None:
        self._c.host.arm.set_position(np.asarray(value, float) / 1e6)


class RapidController:
    """The interpreted module as the simulated controller (see the module docstring)."""

    def __init__(
        self,
        clock: SimClock,
        temperatures: Callable[[float], np.ndarray],
        robot_model: str,
        home_q_rad: np.ndarray,
        faults: FaultPlan | None = None,
        transport: str = "pty",
        estop_at_stop: int | None = None,
        link_timeout_s: float = 1.0,
        module: Path = MODULE,
    ) -> None:
        if transport not in ("pty", "socket"):
            raise ValueError(f"transport {transport!r} must be 'pty' or 'socket'")
        self.clock, self.transport = clock, transport
        self.faults = faults or FaultPlan()
        self.estop_at_stop = estop_at_stop
        self._estop_done = False
        self.error: RapidStopped | None = None
        n_sensors = len(np.atleast_1d(temperatures(clock.now())))
        self.program = Program.from_file(module, consts={
            "HC_MODEL": robot_model, "HC_NAME": "holecell-sim-rapid",
            "HC_LINK_TIMEOUT_S": float(link_timeout_s), "HC_N_TEMPS": n_sensors,
            "HC_TRANSPORT": "serial" if transport == "pty" else "socket"})  # fmt: skip
        self.wire = WireFaults(self.faults)
        self._master = self._slave = None
        if transport == "pty":
            self._master, self._slave = os.openpty()
            tty.setraw(self._slave)
            os.set_blocking(self._master, False)
            self.url = os.ttyname(self._slave)
        q0_deg = np.asarray(m.rad_to_wire(home_q_rad), float) / 1e6
        self.host = SimHost(clock, temperatures, n_sensors, q0_deg, self.wire, self._master)
        g, slot = self.program.state.globals, self.program.scope.lookup("hcAtStop").slot
        self.host.estop_check = lambda: self._estop_due(g[slot])
        self.s = RapidState(self)
        self._thread: threading.Thread | None = None
        self._closed = False

    # --- what SimServer offers ------------------------------------------------------------
    @property
    def requests(self) -> int:
        return self.wire.requests

    @property
    def dropped(self) -> int:
        return self.wire.dropped

    @property
    def corrupted(self) -> int:
        return self.wire.corrupted

    @property
    def disconnects(self) -> int:
        return self.wire.disconnects

    @property
    def controller(self) -> RapidController:
        return self

    def start(self) -> RapidController:
        """Start the program in a daemon thread; for a socket, wait until it listens."""
        if self._thread is not None:
            return self
        self._thread = threading.Thread(target=self._run, name="holecell-rapid", daemon=True)
        self._thread.start()
        if self.transport == "socket":
            if not self.host.bound.wait(10.0):
                self.close()
                raise RuntimeError(f"the RAPID module did not listen: {self.error}")
            self.url = f"socket://127.0.0.1:{self.host.bound_port}"
        return self

    def close(self) -> None:
        """Stop the program and release the pty; closing again does nothing."""
        self.host.halt_request = "shutdown"
        if self._thread is not None:
            self._thread.join(timeout=5.0)
        if self._closed:
            return
        self._closed = True
        for fd in (self._master, self._slave):
            if fd is not None:
                os.close(fd)

    def __enter__(self) -> RapidController:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.close()

    def serve_forever(self) -> None:
        self.start()
        self._thread.join()

    # --- what SimController offers --------------------------------------------------------
    def q_rad(self) -> np.ndarray:
        """The arm's joints now (rad)."""
        return np.deg2rad(self.host.arm.position())

    def update(self) -> None:
        """The program runs on its own; nothing to advance."""

    # --- the program ------------------------------------------------------------------------
    def _estop_due(self, at_stop) -> bool:
        if self.estop_at_stop is None or self._estop_done or int(at_stop) != self.estop_at_stop:
            return False
        self._estop_done = True
        return True

    def _run(self) -> None:
        while True:
            try:
                self.program.run("hcMain", self.host)
                return
            except ProgramHalt as h:
                if h.reason == "shutdown":
                    return
                log.info("emergency stop: program stopped, hcOnEstop, restart at hcMain")
                self.host.arm.halt()
                self.program.run("hcOnEstop", self.host)
            except RapidStopped as e:
                log.error("RAPID program stopped: %s", e)
                self.error = e
                return
