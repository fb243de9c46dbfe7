"""Message types and payload layouts of the controller link (``docs/protocol.md``).

Joint values travel as int32 micro-degrees, temperatures as int32 milli-degrees Celsius, times as
int32 microseconds: the controller's units, exact integers that RAPID reads without rounding
surprises. The conversion to SI (rad, s) happens here, at the edge, and nowhere else.
"""

from __future__ import annotations

import math
import struct
from dataclasses import dataclass
from enum import IntEnum

import numpy as np

from cell.link.errors import PayloadError

PROTOCOL_VERSION = 1
N_JOINTS = 6
#: trajectory rows per LOAD_ROWS frame (6 x int32 each) and stops per LOAD_STOPS frame
ROWS_PER_CHUNK = 20
STOPS_PER_CHUNK = 100
UDEG_PER_RAD = 180.0e6 / math.pi


class Msg(IntEnum):
    """Message type codes (one byte). Requests go host -> controller, ACK/NAK come back."""

    IDENTIFY = 0x01
    HEARTBEAT = 0x02
    STATUS = 0x03
    LOAD_BEGIN = 0x10
    LOAD_ROWS = 0x11
    LOAD_STOPS = 0x12
    LOAD_END = 0x13
    EXECUTE = 0x20
    MOVE_TO_STOP = 0x21
    STOP = 0x22
    ABORT = 0x23
    RESET = 0x24
    ACK = 0x80
    NAK = 0x81


class Nak(IntEnum):
    """NAK reason codes."""

    CRC = 1
    UNKNOWN_TYPE = 2
    BAD_PAYLOAD = 3
    REFUSED = 4
    NOT_LOADED = 5


class State(IntEnum):
    """Controller states reported by STATUS."""

    IDLE = 0
    MOVING = 1
    IN_POSITION = 2
    STOPPED = 3
    ESTOP = 4
    FAULT = 5


class Fault(IntEnum):
    """Fault codes reported by STATUS (the latest fault; NONE after RESET)."""

    NONE = 0
    ESTOP = 1
    LINK_LOST = 2
    OFF_PATH = 3
    LOAD_ERROR = 4


def rad_to_wire(q_rad: np.ndarray) -> list[int]:
    """Joint vector (rad) -> int32 micro-degrees."""
    return [round(float(v) * UDEG_PER_RAD) for v in np.asarray(q_rad, dtype=float).ravel()]


def wire_to_rad(q_udeg: tuple[int, ...] | list[int]) -> np.ndarray:
    """int32 micro-degrees -> joint vector (rad)."""
    return np.asarray(q_udeg, dtype=float) / UDEG_PER_RAD


def _unpack(fmt: struct.Struct, payload: bytes, msg: int, offset: int = 0) -> tuple:
    if len(payload) < offset + fmt.size:
        raise PayloadError(msg, f"needs {offset + fmt.size} bytes, got {len(payload)}")
    return fmt.unpack_from(payload, offset)


# --- identify -------------------------------------------------------------------------------
_IDENT = struct.Struct("<HB")


@dataclass(frozen=True)
class Identity:
    """IDENTIFY answer: protocol version, joint count, robot model and controller names."""

    version: int
    n_joints: int
    robot_model: str
    controller: str

    def pack(self) -> bytes:
        model, ctrl = self.robot_model.encode(), self.controller.encode()
        return (
            _IDENT.pack(self.version, self.n_joints)
            + bytes([len(model)])
            + model
            + bytes([len(ctrl)])
            + ctrl
        )

    @classmethod
    def unpack(cls, payload: bytes) -> Identity:
        version, n = _unpack(_IDENT, payload, Msg.IDENTIFY)
        try:
            pos = _IDENT.size
            n_model = payload[pos]
            model = payload[pos + 1 : pos + 1 + n_model].decode()
            pos += 1 + n_model
            n_ctrl = payload[pos]
            ctrl = payload[pos + 1 : pos + 1 + n_ctrl].decode()
        except (IndexError, UnicodeDecodeError) as exc:
            raise PayloadError(Msg.IDENTIFY, f"bad names: {exc}") from exc
        return cls(version, n, model, ctrl)


# --- status ---------------------------------------------------------------------------------
_STATUS = struct.Struct("<BBhhIIq6iB")


@dataclass(frozen=True)
class Status:
    """STATUS answer in SI units: state, latest fault, the stop the arm is at (-1: none), the stop
    it is moving to (-1: none), trajectory row, loaded trajectory id (0: none), controller clock
    (s), joint positions (rad) and temperatures (degC, one per sensor)."""

    state: State
    fault: Fault
    at_stop: int
    target_stop: int
    row: int
    traj_id: int
    time_s: float
    q_rad: np.ndarray
    temperatures_c: np.ndarray

    def pack(self) -> bytes:
        temps = [round(float(t) * 1000.0) for t in self.temperatures_c]
        head = _STATUS.pack(
            int(self.state),
            int(self.fault),
            self.at_stop,
            self.target_stop,
            self.row,
            self.traj_id,
            round(self.time_s * 1e6),
            *rad_to_wire(self.q_rad),
            len(temps),
        )
        return head + struct.pack(f"<{len(temps)}i", *temps)

    @classmethod
    def unpack(cls, payload: bytes) -> Status:
        v = _unpack(_STATUS, payload, Msg.STATUS)
        n_t = v[13]
        temps = _unpack(struct.Struct(f"<{n_t}i"), payload, Msg.STATUS, _STATUS.size)
        try:
            state, fault = State(v[0]), Fault(v[1])
        except ValueError as exc:
            raise PayloadError(Msg.STATUS, str(exc)) from exc
        return cls(
            state,
            fault,
            v[2],
            v[3],
            v[4],
            v[5],
            v[6] / 1e6,
            wire_to_rad(v[7:13]),
            np.asarray(temps, dtype=float) / 1000.0,
        )


# --- trajectory loading ---------------------------------------------------------------------
LOAD_BEGIN = struct.Struct("<IIHi")  # traj_id, n_rows, n_stops, dt_us
LOAD_ROWS_HEAD = struct.Struct("<IB")  # first row, count
LOAD_STOPS_HEAD = struct.Struct("<HB")  # first stop, count
U32 = struct.Struct("<I")
U16 = struct.Struct("<H")
U8 = struct.Struct("<B")


def pack_rows(first: int, rows_udeg: np.ndarray) -> bytes:
    """LOAD_ROWS payload: ``rows_udeg`` is (count, 6) int micro-degrees."""
    rows = np.asarray(rows_udeg, dtype="<i4").reshape(-1, N_JOINTS)
    return LOAD_ROWS_HEAD.pack(first, rows.shape[0]) + rows.tobytes()


def unpack_rows(payload: bytes) -> tuple[int, np.ndarray]:
    """(first row, (count, 6) int32 micro-degrees) from a LOAD_ROWS payload."""
    first, count = _unpack(LOAD_ROWS_HEAD, payload, Msg.LOAD_ROWS)
    need = LOAD_ROWS_HEAD.size + count * N_JOINTS * 4
    if len(payload) != need or count == 0:
        raise PayloadError(Msg.LOAD_ROWS, f"{count} rows need {need} bytes, got {len(payload)}")
    data = np.frombuffer(payload, dtype="<i4", offset=LOAD_ROWS_HEAD.size)
    return first, data.reshape(count, N_JOINTS).astype(np.int64)


def pack_stops(first: int, rows: list[int]) -> bytes:
    """LOAD_STOPS payload: the trajectory row of stops ``first .. first+len(rows)-1``."""
    return LOAD_STOPS_HEAD.pack(first, len(rows)) + struct.pack(f"<{len(rows)}I", *rows)


def unpack_stops(payload: bytes) -> tuple[int, list[int]]:
    """(first stop, rows) from a LOAD_STOPS payload."""
    first, count = _unpack(LOAD_STOPS_HEAD, payload, Msg.LOAD_STOPS)
    if len(payload) != LOAD_STOPS_HEAD.size + 4 * count or count == 0:
        raise PayloadError(Msg.LOAD_STOPS, f"{count} stops do not match {len(payload)} bytes")
    return first, list(struct.unpack_from(f"<{count}I", payload, LOAD_STOPS_HEAD.size))


def trajectory_id(rows_udeg: np.ndarray, stop_rows: list[int]) -> int:
    """CRC-32 of the wire rows and stop rows: both sides compute it to confirm a load."""
    from cell.link.frame import crc32

    rows = np.asarray(rows_udeg, dtype="<i4").tobytes()
    stops = struct.pack(f"<{len(stop_rows)}I", *stop_rows)
    return crc32(rows + stops) or 1
