"""Payloads and the simulated controller under arbitrary input: clear errors, never a crash."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cell.link import frame as fr
from cell.link import messages as m
from cell.link.errors import PayloadError
from cell.sim.controller import SimController
from cell.sim.world import SimClock

HOME = np.zeros(6)


@settings(max_examples=300, deadline=None)
@given(st.binary(max_size=120))
def test_unpackers_raise_only_payload_errors(data: bytes) -> None:
    for unpack in (m.Status.unpack, m.Identity.unpack, m.unpack_rows, m.unpack_stops):
        try:
            unpack(data)
        except PayloadError as exc:
            assert "message type" in str(exc)


@settings(max_examples=300, deadline=None)
@given(st.lists(st.tuples(st.sampled_from([*m.Msg, 0x55]), st.binary(max_size=60)),
                max_size=12))  # fmt: skip
def test_controller_answers_every_frame_with_ack_or_nak(requests: list) -> None:
    ctrl = SimController(SimClock(100.0), lambda t: np.array([20.0]), "x", HOME)
    for seq, (msg_type, payload) in enumerate(requests):
        wire = ctrl.handle(fr.Frame(int(msg_type), seq & 0xFF, payload))
        (answer,) = fr.FrameDecoder().feed(wire)
        assert answer.type in (m.Msg.ACK, m.Msg.NAK) and answer.seq == seq & 0xFF
        ctrl.update()


def test_repeated_request_is_answered_from_cache_without_acting_twice() -> None:
    ctrl = SimController(SimClock(1.0), lambda t: np.array([20.0]), "x", HOME)
    begin = m.LOAD_BEGIN.pack(7, 2, 0, 4000)
    first = ctrl.handle(fr.Frame(m.Msg.LOAD_BEGIN, 5, begin))
    load = ctrl._load
    assert ctrl.handle(fr.Frame(m.Msg.LOAD_BEGIN, 5, begin)) == first
    assert ctrl._load is load  # not started again
    assert ctrl.handle(fr.Frame(m.Msg.LOAD_BEGIN, 6, begin)) == fr.encode(m.Msg.ACK, 6, b"\x00")
    assert ctrl._load is not load


def test_joint_units_at_the_edge() -> None:
    q = np.array([np.pi, -np.pi / 2, 0.1, 1e-7, 2.0, -3.0])
    wire = m.rad_to_wire(q)
    assert wire[0] == 180_000_000 and wire[1] == -90_000_000
    np.testing.assert_allclose(m.wire_to_rad(wire), q, atol=1e-8)


def test_sim_cli_prints_both_urls(capsys: pytest.CaptureFixture) -> None:
    from cell.cli import main

    assert main(["sim", "--duration-s", "0.2", "--transport", "socket"]) == 0
    out = capsys.readouterr().out
    assert "controller  socket://127.0.0.1:" in out and "camera      tcp://127.0.0.1:" in out
