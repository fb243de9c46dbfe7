"""The simulated controller's protocol and motion logic, independent of the transport.

Motion follows the loaded trajectory row by row at the trajectory's ``dt`` in simulation time,
forwards or backwards, so every motion stays on the planned collision-free path. A stop (STOP,
a lost link, an emergency stop) halts on the path; a later MOVE_TO_STOP continues from there.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from cell.link import frame as fr
from cell.link import messages as m
from cell.link.errors import PayloadError
from cell.sim.world import SimClock

log = logging.getLogger(__name__)

#: a joint vector lies on the trajectory if every joint is within this of a row (micro-degrees)
ON_PATH_TOL_UDEG = 1000
#: largest trajectory the simulated controller holds (rows, about 13 min at 4 ms) and stops
MAX_ROWS = 200_000
MAX_STOPS = 5_000


@dataclass
class _Load:
    traj_id: int
    rows: np.ndarray
    stops: np.ndarray
    dt_s: float
    have_rows: np.ndarray
    have_stops: np.ndarray


@dataclass
class SimControllerState:
    """Everything the controller knows; read by the simulated camera and tests."""

    state: m.State = m.State.IDLE
    fault: m.Fault = m.Fault.NONE
    rows: np.ndarray | None = None  # (N, 6) int micro-degrees
    stops: np.ndarray | None = None
    dt_s: float = 0.004
    traj_id: int = 0
    pos: float = 0.0  # fractional row
    target_row: int | None = None
    target_stop: int = -1
    at_stop: int = -1
    q_udeg: np.ndarray = field(default_factory=lambda: np.zeros(6))
    estop_done: bool = False


class SimController:
    """Answers requests (:meth:`handle`) and moves the arm (:meth:`update`).

    ``temperatures(t_s)`` gives the sensor readings (degC) at simulation time ``t_s``
    (:meth:`cell.sim.world.SimWorld.temperatures` in a full simulation)."""

    def __init__(
        self,
        clock: SimClock,
        temperatures: Callable[[float], np.ndarray],
        robot_model: str,
        home_q_rad: np.ndarray,
        estop_at_stop: int | None = None,
        link_timeout_s: float = 1.0,
    ) -> None:
        self.clock = clock
        self.temperatures = temperatures
        self.robot_model = robot_model
        self.estop_at_stop = estop_at_stop
        self.link_timeout_s = link_timeout_s
        self.s = SimControllerState(q_udeg=np.array(m.rad_to_wire(home_q_rad), dtype=float))
        self._t_last = clock.now()
        self._last_rx = time.monotonic()
        self._cache: tuple[int, bytes, bytes] | None = None
        self._load: _Load | None = None

    # --- motion ---------------------------------------------------------------------------
    def q_rad(self) -> np.ndarray:
        """Current joint positions (rad)."""
        return m.wire_to_rad(self.s.q_udeg)

    def update(self) -> None:
        """Advance the motion to the current simulation time; watch the link."""
        now = self.clock.now()
        dt_sim, self._t_last = now - self._t_last, now
        s = self.s
        if s.state == m.State.MOVING and time.monotonic() - self._last_rx > self.link_timeout_s:
            log.info("link lost: stopping on the path at row %.1f", s.pos)
            self._halt(m.State.STOPPED, m.Fault.LINK_LOST)
            return
        if s.state != m.State.MOVING or s.target_row is None or s.rows is None:
            return
        step = dt_sim / s.dt_s
        delta = s.target_row - s.pos
        s.pos = float(s.target_row) if abs(delta) <= step else s.pos + np.sign(delta) * step
        s.q_udeg = self._interp(s.pos)
        if s.pos == s.target_row:
            s.at_stop, s.target_stop, s.target_row = s.target_stop, -1, None
            s.state = m.State.IN_POSITION
            if s.at_stop == self.estop_at_stop and not s.estop_done:
                s.estop_done = True
                self._halt(m.State.ESTOP, m.Fault.ESTOP)

    def _interp(self, pos: float) -> np.ndarray:
        rows = self.s.rows
        i = min(int(np.floor(pos)), len(rows) - 1)
        j = min(i + 1, len(rows) - 1)
        f = pos - i
        return (1.0 - f) * rows[i] + f * rows[j]

    def _halt(self, state: m.State, fault: m.Fault) -> None:
        s = self.s
        s.state, s.fault, s.target_row, s.target_stop = state, fault, None, -1
        if state != m.State.IN_POSITION:
            s.at_stop = -1

    # --- requests -------------------------------------------------------------------------
    def handle(self, f: fr.Frame) -> bytes:
        """Wire bytes of the answer to one valid request frame (repeats answered from cache)."""
        self._last_rx = time.monotonic()
        key = fr.crc32(bytes([f.type, f.seq]) + f.payload)
        if f.type != m.Msg.IDENTIFY and self._cache and self._cache[:2] == (f.seq, key):
            return self._cache[2]
        self.update()
        try:
            answer = fr.encode(m.Msg.ACK, f.seq, self._dispatch(f))
        except PayloadError as exc:
            answer = fr.encode(m.Msg.NAK, f.seq, bytes([m.Nak.BAD_PAYLOAD]) + str(exc).encode())
        except _RefusedError as exc:
            answer = fr.encode(m.Msg.NAK, f.seq, bytes([exc.code]) + exc.text.encode())
        self._cache = (f.seq, key, answer)
        return answer

    def _dispatch(self, f: fr.Frame) -> bytes:
        handler = _HANDLERS.get(f.type)
        if handler is None:
            raise _RefusedError(m.Nak.UNKNOWN_TYPE, f"unknown message type 0x{f.type:02X}")
        return handler(self, f.payload)

    def _identify(self, _: bytes) -> bytes:
        self._cache = None
        return m.Identity(m.PROTOCOL_VERSION, 6, self.robot_model, "holecell-sim").pack()

    def _heartbeat(self, _: bytes) -> bytes:
        return b""

    def _status(self, _: bytes) -> bytes:
        s, now = self.s, self.clock.now()
        return m.Status(
            s.state,
            s.fault,
            s.at_stop,
            s.target_stop,
            round(s.pos),
            s.traj_id,
            now,
            self.q_rad(),
            self.temperatures(now),
        ).pack()

    def _load_begin(self, p: bytes) -> bytes:
        self._require_not(m.State.MOVING, "cannot load while moving")
        traj_id, n_rows, n_stops, dt_us = m._unpack(m.LOAD_BEGIN, p, m.Msg.LOAD_BEGIN)
        if traj_id == self.s.traj_id and self.s.rows is not None:
            return b"\x01"
        if not 2 <= n_rows <= MAX_ROWS or n_stops > MAX_STOPS or dt_us <= 0:
            raise PayloadError(
                m.Msg.LOAD_BEGIN,
                f"{n_rows} rows (2..{MAX_ROWS}), {n_stops} stops (<= {MAX_STOPS}), dt {dt_us} us",
            )
        self._load = _Load(
            traj_id,
            np.zeros((n_rows, 6)),
            np.zeros(n_stops, dtype=np.int64),
            dt_us / 1e6,
            np.zeros(n_rows, dtype=bool),
            np.zeros(n_stops, dtype=bool),
        )
        return b"\x00"

    def _load_rows(self, p: bytes) -> bytes:
        ld = self._need_load()
        first, rows = m.unpack_rows(p)
        if first + len(rows) > len(ld.rows):
            raise PayloadError(m.Msg.LOAD_ROWS, f"rows {first}+{len(rows)} beyond {len(ld.rows)}")
        ld.rows[first : first + len(rows)] = rows
        ld.have_rows[first : first + len(rows)] = True
        return b""

    def _load_stops(self, p: bytes) -> bytes:
        ld = self._need_load()
        first, rows = m.unpack_stops(p)
        if first + len(rows) > len(ld.stops) or max(rows) >= len(ld.rows):
            raise PayloadError(m.Msg.LOAD_STOPS, f"stops {first}+{len(rows)} out of range")
        ld.stops[first : first + len(rows)] = rows
        ld.have_stops[first : first + len(rows)] = True
        return b""

    def _load_end(self, p: bytes) -> bytes:
        ld = self._need_load()
        (traj_id,) = m._unpack(m.U32, p, m.Msg.LOAD_END)
        if not (ld.have_rows.all() and ld.have_stops.all()):
            raise _RefusedError(m.Nak.REFUSED, "rows or stops missing")
        if traj_id != ld.traj_id or m.trajectory_id(ld.rows, list(ld.stops)) != traj_id:
            raise _RefusedError(m.Nak.REFUSED, "trajectory id does not match the data")
        s, self._load = self.s, None
        s.rows, s.stops, s.dt_s, s.traj_id = ld.rows, ld.stops, ld.dt_s, traj_id
        err = np.abs(ld.rows - s.q_udeg).max(axis=1)
        on_path = np.flatnonzero(err <= ON_PATH_TOL_UDEG)
        if on_path.size == 0:
            s.rows, s.traj_id = None, 0
            s.state, s.fault = m.State.FAULT, m.Fault.OFF_PATH
            raise _RefusedError(m.Nak.REFUSED, "the arm is not on the trajectory: jog it home")
        s.pos = float(on_path[0])
        stop_here = np.flatnonzero(ld.stops == on_path[0])
        s.at_stop = int(stop_here[0]) if stop_here.size else -1
        s.state = m.State.IN_POSITION if s.at_stop >= 0 else m.State.IDLE
        return b""

    def _need_load(self) -> _Load:
        if self._load is None:
            raise _RefusedError(m.Nak.NOT_LOADED, "no load in progress (LOAD_BEGIN first)")
        return self._load

    def _require_not(self, state: m.State, text: str) -> None:
        if self.s.state == state:
            raise _RefusedError(m.Nak.REFUSED, text)

    def _start(self, row: int, stop: int) -> None:
        s = self.s
        if s.state in (m.State.ESTOP, m.State.FAULT):
            raise _RefusedError(m.Nak.REFUSED, f"{s.state.name}: {s.fault.name}; RESET first")
        s.target_row, s.target_stop, s.at_stop = row, stop, -1
        s.state = m.State.MOVING
        self.update()

    def _move_to_stop(self, p: bytes) -> bytes:
        (k,) = m._unpack(m.U16, p, m.Msg.MOVE_TO_STOP)
        s = self.s
        if s.rows is None or s.stops is None:
            raise _RefusedError(m.Nak.NOT_LOADED, "no trajectory loaded")
        if k > len(s.stops):
            raise PayloadError(m.Msg.MOVE_TO_STOP, f"stop {k} of {len(s.stops)}")
        row = len(s.rows) - 1 if k == len(s.stops) else int(s.stops[k])
        self._start(row, k)
        return b""

    def _execute(self, _: bytes) -> bytes:
        if self.s.rows is None or self.s.stops is None:
            raise _RefusedError(m.Nak.NOT_LOADED, "no trajectory loaded")
        self._start(len(self.s.rows) - 1, len(self.s.stops))
        return b""

    def _stop(self, _: bytes) -> bytes:
        if self.s.state == m.State.MOVING:
            self._halt(m.State.STOPPED, m.Fault.NONE)
        return b""

    def _abort(self, _: bytes) -> bytes:
        self._stop(b"")
        s = self.s
        s.rows, s.stops, s.traj_id, s.at_stop = None, None, 0, -1
        if s.state not in (m.State.ESTOP, m.State.FAULT):
            s.state = m.State.IDLE
        return b""

    def _reset(self, _: bytes) -> bytes:
        s = self.s
        if s.state in (m.State.ESTOP, m.State.FAULT):
            s.state = m.State.STOPPED if s.rows is not None else m.State.IDLE
        s.fault = m.Fault.NONE
        return b""


class _RefusedError(Exception):
    def __init__(self, code: int, text: str) -> None:
        self.code, self.text = code, text
        super().__init__(text)


_HANDLERS = {
    m.Msg.IDENTIFY: SimController._identify,
    m.Msg.HEARTBEAT: SimController._heartbeat,
    m.Msg.STATUS: SimController._status,
    m.Msg.LOAD_BEGIN: SimController._load_begin,
    m.Msg.LOAD_ROWS: SimController._load_rows,
    m.Msg.LOAD_STOPS: SimController._load_stops,
    m.Msg.LOAD_END: SimController._load_end,
    m.Msg.EXECUTE: SimController._execute,
    m.Msg.MOVE_TO_STOP: SimController._move_to_stop,
    m.Msg.STOP: SimController._stop,
    m.Msg.ABORT: SimController._abort,
    m.Msg.RESET: SimController._reset,
}
