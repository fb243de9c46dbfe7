"""The link client against the simulated controller over a pty and a socket, with faults: the
Python stand-in (``python``) and the shipped RAPID module in the interpreter (``rapid``)."""

from __future__ import annotations

import time

import numpy as np
import pytest

from cell.link import messages as m
from cell.link.client import ControllerClient, LinkOptions
from cell.link.errors import LinkError, RequestRefusedError
from cell.sim.controller import SimController
from cell.sim.faults import FaultPlan
from cell.sim.rapid_controller import RapidController
from cell.sim.server import SimServer
from cell.sim.world import SimClock

HOME = np.array([0.0, -0.3, 0.4, 0.0, 0.5, 0.0])
FAST = LinkOptions(response_timeout_s=0.03, retries=40, heartbeat_period_s=0.05)
#: the interpreted module answers a full LOAD_ROWS frame in tens of ms (a real serial line at
#: 115200 baud needs 45 ms to carry one): the client's default response timeout
FAST_RAPID = LinkOptions(response_timeout_s=0.15, retries=40, heartbeat_period_s=0.05)


def _fast(controller: str) -> LinkOptions:
    return FAST_RAPID if controller == "rapid" else FAST


def _trajectory(n: int = 200) -> tuple[np.ndarray, list[int]]:
    s = np.linspace(0.0, 1.0, n)[:, None]
    out = HOME + np.sin(np.pi * s) * np.array([0.5, 0.2, -0.1, 1.0, 0.3, -2.0])
    return out, [50, 100, 150]


@pytest.fixture(params=["python", "rapid"])
def controller(request) -> str:
    return request.param


def _server(controller: str, faults: FaultPlan | None = None, transport: str = "pty", **kw):
    temps = lambda t: np.array([20.0 + 0.01 * t, 21.0])  # noqa: E731
    clock = SimClock(kw.pop("speed", 50.0))
    if controller == "rapid":
        return RapidController(clock, temps, "abb_test", HOME, faults, transport, **kw).start()
    ctrl = SimController(clock, temps, "abb_test", HOME, **kw)
    return SimServer(ctrl, faults, transport).start()


@pytest.mark.parametrize("transport", ["pty", "socket"])
def test_identify_load_move_and_status(transport: str, controller: str) -> None:
    q, stops = _trajectory()
    with (
        _server(controller, transport=transport) as sim,
        ControllerClient(sim.url, _fast(controller)) as c,
    ):
        assert c.identity.robot_model == "abb_test" and c.identity.version == m.PROTOCOL_VERSION
        traj_id = c.load_trajectory(q, stops, 0.004)
        assert c.load_trajectory(q, stops, 0.004) == traj_id  # already loaded: no transfer
        for k in range(len(stops)):
            c.move_to_stop(k)
            st = c.wait_in_position(k, timeout_s=5.0)
            assert st.state == m.State.IN_POSITION and st.at_stop == k
            np.testing.assert_allclose(st.q_rad, q[stops[k]], atol=1e-7)
        c.move_to_stop(len(stops))
        st = c.wait_in_position(len(stops), timeout_s=5.0)
        np.testing.assert_allclose(st.q_rad, q[-1], atol=1e-7)
        assert st.temperatures_c.shape == (2,) and st.traj_id == traj_id


def test_moves_backwards_along_the_path_and_stop_holds(controller: str) -> None:
    q, stops = _trajectory()
    # real time: stop 2 is 0.4 s of motion away, and the stop is sent as soon as the arm is
    # seen moving (no fixed sleep that a loaded machine could outlast)
    with (
        _server(controller, speed=1.0) as sim,
        ControllerClient(sim.url, _fast(controller)) as c,
    ):
        c.load_trajectory(q, stops, 0.004)
        c.move_to_stop(2)
        st = c.status()
        while st.row == 0:  # until the arm is seen on its way
            st = c.status()
        c.stop()
        st = c.status()
        # where the arm holds, by its joints: the RAPID module reports row 0 ("not on a row")
        # when the halt falls between two rows, which is where it usually falls
        way = q[: stops[2] + 1]
        nearest = int(np.argmin(np.abs(way - st.q_rad).max(axis=1)))
        assert st.state == m.State.STOPPED and nearest < stops[2]
        assert np.abs(st.q_rad - q[0]).max() > 0  # it had left the start
        assert np.abs(way[nearest] - st.q_rad).max() <= np.abs(np.diff(q, axis=0)).max()
        c.move_to_stop(0)
        st = c.wait_in_position(0, timeout_s=5.0)
        np.testing.assert_allclose(st.q_rad, q[stops[0]], atol=1e-7)


def test_faulty_line_still_delivers_every_request_once(controller: str) -> None:
    q, stops = _trajectory(600)
    faults = FaultPlan(drop=0.05, corrupt=0.05, delay=0.05, delay_s=0.04, seed=3)
    with _server(controller, faults) as sim, ControllerClient(sim.url, _fast(controller)) as c:
        c.load_trajectory(q, stops, 0.004)
        for k in range(len(stops)):
            c.move_to_stop(k)
            assert c.wait_in_position(k, timeout_s=10.0).at_stop == k
        assert sim.dropped > 0 and sim.corrupted > 0
        assert c.stats.retransmits > 0


def test_estop_latches_until_reset(controller: str) -> None:
    q, stops = _trajectory()
    with (
        _server(controller, estop_at_stop=1) as sim,
        ControllerClient(sim.url, _fast(controller)) as c,
    ):
        c.load_trajectory(q, stops, 0.004)
        c.move_to_stop(1)
        st = c.wait_in_position(1, timeout_s=5.0)
        assert st.state == m.State.ESTOP and st.fault == m.Fault.ESTOP
        with pytest.raises(RequestRefusedError, match="RESET"):
            c.move_to_stop(2)
        c.reset()
        c.move_to_stop(1)
        assert c.wait_in_position(1, timeout_s=5.0).state == m.State.IN_POSITION


def test_link_loss_stops_the_arm_on_the_path(controller: str) -> None:
    # the interpreted module loads 2000 rows in seconds: 600 (2.2 s of motion) are enough there
    n = 600 if controller == "rapid" else 2000
    q, _ = _trajectory(n)
    with _server(controller, speed=1.0, link_timeout_s=0.1) as sim:
        c = ControllerClient(sim.url, LinkOptions(response_timeout_s=0.03, heartbeat_period_s=60))
        c.connect()
        c.load_trajectory(q, [n - 50], 0.004)
        c.move_to_stop(0)
        c._stop_hb.set()
        time.sleep(0.3)
        if controller == "python":  # a status request would feed the watchdog: wait without
            # one until the simulator's loop has run (it may not have, on a loaded machine)
            deadline = time.monotonic() + 30.0
            while sim.controller.s.state == m.State.MOVING and time.monotonic() < deadline:
                time.sleep(0.05)
        st = c.status()
        assert st.state == m.State.STOPPED and st.fault == m.Fault.LINK_LOST
        assert 0 < st.row < n - 50
        c.close()


def test_socket_disconnect_then_reconnect(controller: str) -> None:
    faults = FaultPlan(disconnect_after=5, disconnect_s=0.2)
    with _server(controller, faults, transport="socket") as sim:
        c = ControllerClient(sim.url, LinkOptions(response_timeout_s=0.03, retries=3))
        c.connect()
        with pytest.raises(LinkError):
            for _ in range(10):
                c.status()
        c.reconnect(budget_s=5.0)
        assert c.status().state == m.State.IDLE
        c.close()


def test_bad_port_gives_clear_error() -> None:
    with pytest.raises(LinkError, match="/dev/does-not-exist"):
        ControllerClient("/dev/does-not-exist", LinkOptions(open_timeout_s=0.1)).connect()
