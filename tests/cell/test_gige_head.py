"""The GigE Vision head over real GVCP/GVSP on loopback, inside a private network namespace:
two Aravis fake cameras serve known pairs, the holecell client gets them byte for byte, Aravis's
own tool grabs from the simulated head, and injected drops, incomplete frames and mismatched
pairs are retried once and then fail exactly that capture with the reason."""

from __future__ import annotations

import os
import re
import subprocess
import sys

import numpy as np
import pytest
from netns import in_netns

from cell.camera import StereoPair
from cell.camera.errors import PairError

SHAPE = (480, 640)
#: a dropped frame never arrives: the wait for it is the test's length, and long enough that
#: a frame that does come is never taken for a dropped one on a loaded machine
FAST = "?packet_size=8192&timeout_ms=5000"


class Renders:
    """Known random pairs, one per trigger, remembered for comparison."""

    def __init__(self) -> None:
        self.rng = np.random.default_rng(7)
        self.served: list[StereoPair] = []

    def __call__(self) -> StereoPair:
        left, right = (self.rng.integers(0, 256, SHAPE, dtype=np.uint8) for _ in range(2))
        self.served.append(StereoPair(left, right))
        return self.served[-1]


def _head(faults=None):
    from cell.sim.gige_head import GigeHead

    renders = Renders()
    return GigeHead(renders, SHAPE, faults=faults), renders


def _client(url: str):
    from cell.camera.gige import GigeStereo
    from measure.synth import standard_stereo

    return GigeStereo(url, standard_stereo())


def _same(a: StereoPair, b: StereoPair) -> bool:
    return np.array_equal(a.left, b.left) and np.array_equal(a.right, b.right)


@in_netns
def test_pairs_arrive_byte_for_byte_over_gvsp() -> None:
    head, renders = _head()
    with head:
        cam = _client(head.url + FAST)
        try:
            pairs = [cam.capture() for _ in range(3)]
            assert cam.retries == 0 and cam.left.packet_size == 8192
        finally:
            cam.close()
    assert len(renders.served) == 3
    assert all(_same(p, s) for p, s in zip(pairs, renders.served, strict=True))


@in_netns
def test_aravis_own_tool_grabs_from_holecell_sim() -> None:
    env = dict(os.environ, PYTHONUNBUFFERED="1")
    sim = subprocess.Popen([sys.executable, "-m", "cell.cli", "sim", "--camera-transport", "gige",
                            "--duration-s", "120"], env=env, stdout=subprocess.PIPE,
                           stderr=subprocess.STDOUT, text=True)  # fmt: skip
    try:
        lines = [sim.stdout.readline() for _ in range(3)]
        assert "camera      gige://127.0.0.1,127.0.0.2\n" in lines, lines
        # both cameras at once, so that both take the same renders (a render of the simulated
        # head takes 0.3 s, seconds on a loaded machine: a long grab, a slow trigger); a socket
        # buffer sized to the frame (-a) and a frame waited for up to 5 s (-m, -p, -l): a
        # loaded machine's stream thread, late to read, lost packets with the tool's defaults
        tools = [subprocess.Popen(["arv-camera-test-0.8", "-n", ip, "-o", "2", "--duration", "10",
                                   "-a", "-m", "5000", "-p", "1000", "-l", "1000"],
                                  stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
                 for ip in ("127.0.0.1", "127.0.0.2")]  # fmt: skip
        for tool in tools:
            out, _ = tool.communicate(timeout=120)
            assert tool.returncode == 0, out
            assert "image width            = 2448" in out and "image height           = 2048" in out
            done = int(re.search(r"n_completed_buffers\s*=\s*(\d+)", out).group(1))
            failed = int(re.search(r"n_failures\s*=\s*(\d+)", out).group(1))
            assert done >= 1 and failed == 0, out
    finally:
        sim.terminate()
        sim.wait(timeout=30)


@in_netns
def test_a_single_drop_is_retried_and_the_retry_pairs() -> None:
    from cell.sim.gige_head import GigeFaults

    head, renders = _head(GigeFaults({"drop": frozenset({1})}, by="trigger"))
    with head:
        cam = _client(head.url + FAST)
        try:
            first, second = cam.capture(), cam.capture()
            third = cam.capture()
            assert cam.retries == 1
        finally:
            cam.close()
    # trigger 1's right frame was lost: the retry (trigger 2) gave the second pair
    assert _same(first, renders.served[0]) and _same(second, renders.served[2])
    assert _same(third, renders.served[3])


@pytest.mark.parametrize(
    ("kind", "reason"),
    [("drop", "right frame dropped or late"), ("incomplete", "right frame"),
     ("mismatch", "frames of different triggers")],
)  # fmt: skip
@in_netns
def test_a_persistent_fault_fails_that_capture_alone(kind: str, reason: str) -> None:
    from cell.sim.gige_head import GigeFaults

    head, renders = _head(GigeFaults({kind: frozenset({1, 2})}, by="trigger"))
    with head:
        cam = _client(head.url + FAST)
        try:
            first = cam.capture()
            with pytest.raises(PairError) as err:
                cam.capture()
            after = cam.capture()
        finally:
            cam.close()
    msg = str(err.value)
    assert reason in msg and "retried:" in msg and "capture 2" in msg, msg
    if kind == "incomplete":
        assert "incomplete" in msg or "dropped" in msg, msg
    if kind == "mismatch":  # the right camera sends its previous frame again: Aravis drops
        # a stale block id itself (the first attempt times out), the retry's stale frame
        # (the first attempt's, with a newer id) is caught by its timestamp
        assert "intervals" in msg.split("retried:")[1], msg
    assert _same(first, renders.served[0]) and _same(after, renders.served[3])


@in_netns
def test_a_line_trigger_pulsed_over_rws_gives_one_pair_per_pulse() -> None:
    from cell.controller.rws1 import Rws1Manager
    from cell.sim.rws_server import RwsFake

    head, renders = _head()
    edges = []

    def wire(name: str, value: int) -> None:  # the output wired to both cameras' Line0
        if name == "Local/DRV_1/doCamTrigger" and value == 1:
            edges.append(name)
            head.pulse()

    with head, RwsFake(on_signal=wire) as rws:
        manager = Rws1Manager(rws.url, "Default User", "robotics")
        cam = _client(head.url + FAST + "&trigger=line0&pair_ms=250")
        cam.fire = lambda: manager.pulse("doCamTrigger")
        try:
            assert cam.left.camera.get_trigger_source() == "Line0"
            pairs = [cam.capture() for _ in range(2)]
            assert cam.retries == 0
        finally:
            cam.close()
            manager.close()
    assert len(edges) == 2 and rws.signals["Local/DRV_1/doCamTrigger"] == 0
    assert all(_same(p, s) for p, s in zip(pairs, renders.served, strict=True))
