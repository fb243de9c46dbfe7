"""The frame codec of the controller link.

A frame on the wire (all integers little-endian)::

    0xA5 0x5A | type u8 | seq u8 | length u16 | payload (length bytes) | crc u32

``crc`` is CRC-32 (ISO-HDLC: polynomial 0x04C11DB7 reflected, init 0xFFFFFFFF, final XOR
0xFFFFFFFF; :func:`zlib.crc32`) over ``type .. payload``. ``length`` is at most
:data:`MAX_PAYLOAD`. The decoder resynchronises after any corruption: a bad frame drops only its
first sync byte and the buffer is rescanned, so a valid frame that follows garbage is never lost.
"""

from __future__ import annotations

import struct
import zlib
from dataclasses import dataclass

SYNC = b"\xa5\x5a"
HEADER = struct.Struct("<2sBBH")
CRC = struct.Struct("<I")
MAX_PAYLOAD = 512
OVERHEAD = HEADER.size + CRC.size
#: CRC-32 check value of b"123456789" (the catalogue's check value, also asserted in RAPID)
CRC32_CHECK = 0xCBF43926


@dataclass(frozen=True)
class Frame:
    """One decoded frame: message ``type``, sequence number ``seq`` (0..255), ``payload``."""

    type: int
    seq: int
    payload: bytes


def crc32(data: bytes) -> int:
    """CRC-32/ISO-HDLC of ``data`` (the frame check of this protocol)."""
    return zlib.crc32(data) & 0xFFFFFFFF


def encode(msg_type: int, seq: int, payload: bytes = b"") -> bytes:
    """The wire bytes of one frame. Raises ValueError for out-of-range fields."""
    if not 0 <= msg_type <= 0xFF or not 0 <= seq <= 0xFF:
        raise ValueError(f"type {msg_type} and seq {seq} must be 0..255")
    if len(payload) > MAX_PAYLOAD:
        raise ValueError(f"payload of {len(payload)} bytes exceeds {MAX_PAYLOAD}")
    body = bytes((msg_type, seq)) + struct.pack("<H", len(payload)) + payload
    return SYNC + body + CRC.pack(crc32(body))


class FrameDecoder:
    """Incremental decoder: :meth:`feed` bytes as they arrive, get the complete valid frames.

    ``corrupt`` counts rejected frames (bad CRC or impossible length); ``skipped`` counts bytes
    discarded while looking for a sync. :meth:`expire` gives up on a partial frame (call it when
    the line has been idle for a frame time): its sync is dropped and the rest rescanned.
    """

    def __init__(self) -> None:
        self._buf = bytearray()
        self.corrupt = 0
        self.skipped = 0

    @property
    def pending(self) -> int:
        """Bytes buffered that do not yet form a complete frame."""
        return len(self._buf)

    def feed(self, data: bytes) -> list[Frame]:
        """Append ``data`` and return every complete frame whose CRC checks, in order."""
        self._buf.extend(data)
        frames: list[Frame] = []
        while True:
            frame, progressed = self._next()
            if frame is not None:
                frames.append(frame)
            elif not progressed:
                return frames

    def expire(self) -> list[Frame]:
        """Drop a stale partial frame (its sync only) and return frames found behind it."""
        if self._buf.startswith(SYNC):
            self.corrupt += 1
        else:
            self.skipped += min(1, len(self._buf))
        del self._buf[:1]
        return self.feed(b"")

    def _next(self) -> tuple[Frame | None, bool]:
        buf = self._buf
        start = buf.find(SYNC)
        if start < 0:
            keep = 1 if buf.endswith(SYNC[:1]) else 0
            dropped = len(buf) - keep
            if dropped:
                self.skipped += dropped
                del buf[:dropped]
            return None, False
        if start:
            self.skipped += start
            del buf[:start]
        if len(buf) < HEADER.size:
            return None, False
        _, msg_type, seq, length = HEADER.unpack_from(buf)
        if length > MAX_PAYLOAD:
            self.corrupt += 1
            del buf[:1]
            return None, True
        total = HEADER.size + length + CRC.size
        if len(buf) < total:
            return None, False
        body = bytes(buf[2 : HEADER.size + length])
        (crc,) = CRC.unpack_from(buf, HEADER.size + length)
        if crc != crc32(body):
            self.corrupt += 1
            del buf[:1]
            return None, True
        del buf[:total]
        return Frame(msg_type, seq, body[4:]), True
