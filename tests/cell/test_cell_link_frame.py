"""The frame codec: round trips, resynchronisation, and fuzzing (no crash, no corrupt frame)."""

from __future__ import annotations

import zlib

from hypothesis import given, settings
from hypothesis import strategies as st

from cell.link import frame as fr

payloads = st.binary(min_size=0, max_size=fr.MAX_PAYLOAD)
frames = st.tuples(st.integers(0, 255), st.integers(0, 255), payloads)


def _drain(dec: fr.FrameDecoder, data: bytes) -> list[fr.Frame]:
    out = dec.feed(data)
    while dec.pending:
        out += dec.expire()
    return out


def test_crc_is_crc32_iso_hdlc() -> None:
    assert fr.crc32(b"123456789") == fr.CRC32_CHECK == 0xCBF43926
    assert fr.crc32(b"abc") == zlib.crc32(b"abc")


def test_round_trip_byte_by_byte() -> None:
    wire = fr.encode(0x21, 7, b"\x03\x00") + fr.encode(0x80, 7, b"")
    dec = fr.FrameDecoder()
    got = [f for b in wire for f in dec.feed(bytes([b]))]
    assert got == [fr.Frame(0x21, 7, b"\x03\x00"), fr.Frame(0x80, 7, b"")]
    assert dec.corrupt == 0 and dec.pending == 0


def test_encode_rejects_oversize_payload() -> None:
    try:
        fr.encode(1, 1, bytes(fr.MAX_PAYLOAD + 1))
    except ValueError as exc:
        assert "exceeds" in str(exc)
    else:
        raise AssertionError("oversize payload accepted")


@settings(max_examples=300, deadline=None)
@given(
    frames, st.lists(st.tuples(st.integers(0, 10_000), st.integers(0, 7)), min_size=1, max_size=8)
)
def test_corrupted_frame_is_never_accepted(f: tuple[int, int, bytes], flips: list) -> None:
    wire = bytearray(fr.encode(*f))
    for pos, bit in flips:
        wire[pos % len(wire)] ^= 1 << bit
    dec = fr.FrameDecoder()
    got = _drain(dec, bytes(wire))
    if bytes(wire) == fr.encode(*f):  # flips cancelled out
        assert got == [fr.Frame(*f)]
    else:
        assert got == []


@settings(max_examples=200, deadline=None)
@given(st.lists(st.tuples(frames, st.binary(max_size=64)), min_size=1, max_size=6))
def test_valid_frames_survive_garbage_between_them(items: list) -> None:
    wire = b"".join(st_garbage + fr.encode(*f) for f, st_garbage in items)
    got = _drain(fr.FrameDecoder(), wire)
    expected = [fr.Frame(*f) for f, _ in items]
    # every valid frame comes out, in order; garbage never forms a frame with a valid CRC here
    it = iter(got)
    assert all(any(g == e for g in it) for e in expected)


@settings(max_examples=300, deadline=None)
@given(st.binary(max_size=2048), st.integers(1, 64))
def test_decoder_never_crashes_on_arbitrary_bytes(data: bytes, chunk: int) -> None:
    dec = fr.FrameDecoder()
    out: list[fr.Frame] = []
    for i in range(0, len(data), chunk):
        out += dec.feed(data[i : i + chunk])
    while dec.pending:
        out += dec.expire()
    for f in out:  # anything accepted must re-encode to bytes present in the input
        assert fr.encode(f.type, f.seq, f.payload) in data
