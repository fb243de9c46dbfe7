"""The host side of the controller link: requests with retransmission, heartbeat, reconnect.

Stop-and-wait: one request is outstanding at a time; the controller answers every request with
an ACK (carrying the answer) or a NAK, both echoing the request's sequence number. A request
without a valid answer within ``response_timeout_s``, or answered by a CRC NAK, is sent again
with the same sequence number; the controller answers a repeat from its cache without acting
twice. After ``retries`` repeats the link is declared dead (:class:`LinkError`). A heartbeat
that gets no answer declares it dead too: the next request raises :class:`LinkError` at once, so
its caller reconnects (the line may answer again by then, but whatever was in flight is lost).
"""

from __future__ import annotations

import logging
import threading
import time
from dataclasses import dataclass

import numpy as np

from cell.link import frame as fr
from cell.link import messages as m
from cell.link.errors import LinkError, MoveTimeoutError, RequestRefusedError
from cell.link.transport import open_port, read_some, write_all

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class LinkOptions:
    """Link settings. Times are wall-clock seconds."""

    baudrate: int = 115200
    response_timeout_s: float = 0.15
    retries: int = 10
    heartbeat_period_s: float = 0.25
    open_timeout_s: float = 5.0
    poll_period_s: float = 0.004


@dataclass
class LinkStats:
    """Counters of one client: requests, retransmissions, corrupt frames seen, reconnects."""

    requests: int = 0
    retransmits: int = 0
    corrupt: int = 0
    reconnects: int = 0


class ControllerClient:
    """A connection to one controller. Use :meth:`connect` (or ``with``) before requests."""

    def __init__(self, url: str, options: LinkOptions | None = None) -> None:
        self.url = url
        self.options = options or LinkOptions()
        self.stats = LinkStats()
        self.identity: m.Identity | None = None
        self._port = None
        self._decoder = fr.FrameDecoder()
        self._seq = 0
        self._lock = threading.RLock()
        self._last_tx = 0.0
        self._stop_hb = threading.Event()
        self._hb_thread: threading.Thread | None = None
        #: why the heartbeat found the link dead (None: it did not); the next request raises it
        self._lost: str | None = None

    # --- connection -------------------------------------------------------------------------
    def connect(self) -> m.Identity:
        """Open the port, identify the controller and start the heartbeat."""
        with self._lock:
            self._port = open_port(self.url, self.options.baudrate, self.options.open_timeout_s)
            self._decoder = fr.FrameDecoder()
            self._lost = None
            self.identity = m.Identity.unpack(self.request(m.Msg.IDENTIFY))
        if self.identity.version != m.PROTOCOL_VERSION:
            raise LinkError(
                self.url,
                f"controller speaks protocol version {self.identity.version}, "
                f"this host speaks {m.PROTOCOL_VERSION}",
            )
        if self._hb_thread is None:
            self._stop_hb.clear()
            self._hb_thread = threading.Thread(target=self._heartbeat, daemon=True)
            self._hb_thread.start()
        return self.identity

    def reconnect(self, budget_s: float = 10.0) -> m.Identity:
        """Close and reopen the link, retrying for ``budget_s``."""
        deadline = time.monotonic() + budget_s
        while True:
            with self._lock:
                self._close_port()
                self.stats.reconnects += 1
                try:
                    return self.connect()
                except LinkError:
                    if time.monotonic() >= deadline:
                        raise
            time.sleep(0.05)

    def close(self) -> None:
        """Stop the heartbeat and close the port."""
        self._stop_hb.set()
        if self._hb_thread is not None:
            self._hb_thread.join(timeout=1.0)
            self._hb_thread = None
        with self._lock:
            self._close_port()

    def _close_port(self) -> None:
        if self._port is not None:
            try:
                self._port.close()
            except OSError as exc:
                log.info("closing %s: %s", self.url, exc)
            self._port = None

    def __enter__(self) -> ControllerClient:
        self.connect()
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # --- requests ---------------------------------------------------------------------------
    def request(self, msg: m.Msg, payload: bytes = b"") -> bytes:
        """Send one request and return the ACK payload (retransmitting as needed)."""
        with self._lock:
            if self._port is None:
                raise LinkError(self.url, "not connected")
            if self._lost is not None:  # the heartbeat found the line dead: reconnect first
                why, self._lost = self._lost, None
                raise LinkError(self.url, f"the heartbeat got no answer ({why})")
            self._seq = (self._seq + 1) & 0xFF
            seq = self._seq
            wire = fr.encode(msg, seq, payload)
            self.stats.requests += 1
            for attempt in range(self.options.retries + 1):
                if attempt:
                    self.stats.retransmits += 1
                write_all(self._port, wire, self.url)
                self._last_tx = time.monotonic()
                answer = self._await(seq)
                if answer is None:
                    continue
                if answer.type == m.Msg.ACK:
                    return answer.payload
                code = answer.payload[0] if answer.payload else 0
                text = answer.payload[1:].decode(errors="replace")
                raise RequestRefusedError(msg.name, code, text)
            raise LinkError(
                self.url, f"no answer to {msg.name} after {self.options.retries + 1} attempts"
            )

    def _await(self, seq: int) -> fr.Frame | None:
        """The ACK/NAK for ``seq``; None on timeout or CRC NAK (retransmit)."""
        deadline = time.monotonic() + self.options.response_timeout_s
        idle_since = time.monotonic()
        while time.monotonic() < deadline:
            data = read_some(self._port, self.url)
            frames = self._decoder.feed(data) if data else []
            if data:
                idle_since = time.monotonic()
            elif self._decoder.pending and time.monotonic() - idle_since > 0.02:
                frames = self._decoder.expire()
            self.stats.corrupt = self._decoder.corrupt
            for f in frames:
                if f.type == m.Msg.NAK and f.payload[:1] == bytes([m.Nak.CRC]):
                    return None
                if f.seq == seq and f.type in (m.Msg.ACK, m.Msg.NAK):
                    return f
        return None

    def _heartbeat(self) -> None:
        while not self._stop_hb.wait(self.options.heartbeat_period_s / 2):
            if time.monotonic() - self._last_tx < self.options.heartbeat_period_s:
                continue
            try:
                self.request(m.Msg.HEARTBEAT)
            except LinkError as exc:  # the line is dead: the next request says so
                log.info("heartbeat failed: %s", exc)
                with self._lock:
                    self._lost = str(exc)
            except RequestRefusedError as exc:
                log.info("heartbeat refused: %s", exc)

    # --- commands ---------------------------------------------------------------------------
    def status(self) -> m.Status:
        """Joint positions, state, fault, temperatures."""
        return m.Status.unpack(self.request(m.Msg.STATUS))

    def load_trajectory(self, q_rad: np.ndarray, stop_rows: list[int], dt_s: float) -> int:
        """Load the sampled trajectory ``q_rad`` (N, 6) and the row of each stop, in chunks.
        Skips the transfer if the controller already holds the same trajectory. Returns its id."""
        rows = np.array([m.rad_to_wire(q) for q in np.asarray(q_rad, dtype=float)], dtype=np.int64)
        traj_id = m.trajectory_id(rows, stop_rows)
        begin = m.LOAD_BEGIN.pack(traj_id, len(rows), len(stop_rows), round(dt_s * 1e6))
        if self.request(m.Msg.LOAD_BEGIN, begin) == b"\x01":
            return traj_id
        for first in range(0, len(rows), m.ROWS_PER_CHUNK):
            chunk = rows[first : first + m.ROWS_PER_CHUNK]
            self.request(m.Msg.LOAD_ROWS, m.pack_rows(first, chunk))
        for first in range(0, len(stop_rows), m.STOPS_PER_CHUNK):
            chunk_rows = [int(r) for r in stop_rows[first : first + m.STOPS_PER_CHUNK]]
            self.request(m.Msg.LOAD_STOPS, m.pack_stops(first, chunk_rows))
        self.request(m.Msg.LOAD_END, m.U32.pack(traj_id))
        return traj_id

    def execute(self) -> None:
        """Play the loaded trajectory from the current row to its end."""
        self.request(m.Msg.EXECUTE)

    def move_to_stop(self, k: int) -> None:
        """Start moving along the trajectory to stop ``k``; ``k`` = number of stops means the
        trajectory's last row (home)."""
        self.request(m.Msg.MOVE_TO_STOP, m.U16.pack(k))

    def stop(self) -> None:
        """Controlled stop on the path; a later move continues from there."""
        self.request(m.Msg.STOP)

    def abort(self) -> None:
        """Stop on the path and discard the loaded trajectory."""
        self.request(m.Msg.ABORT)

    def reset(self) -> None:
        """Clear a latched fault (an emergency stop must also be released at the cell)."""
        self.request(m.Msg.RESET)

    def wait_in_position(self, k: int, timeout_s: float) -> m.Status:
        """Poll STATUS until the arm reports IN_POSITION at stop ``k``; returns that status.
        Raises :class:`cell.link.errors.MoveTimeoutError` (not a link error: the link answers)
        on timeout, and returns early with any other terminal state (STOPPED, ESTOP, FAULT) for
        the caller to handle."""
        deadline = time.monotonic() + timeout_s
        while True:
            st = self.status()
            if st.state == m.State.IN_POSITION and st.at_stop == k:
                return st
            if st.state in (m.State.STOPPED, m.State.ESTOP, m.State.FAULT, m.State.IDLE):
                return st
            if time.monotonic() > deadline:
                raise MoveTimeoutError(self.url, k, timeout_s, st.state.name)
            time.sleep(self.options.poll_period_s)
