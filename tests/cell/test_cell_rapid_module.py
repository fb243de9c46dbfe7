"""The shipped module in the interpreter on tours past num's exact integers: J1 at +-150 deg and
J6 past +-300 deg load and run; the id the module computed before issue 20 (rows in num degrees,
micro-degrees rebuilt with Round) would have refused such a tour."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from cell.link import messages as m
from cell.link.client import ControllerClient, LinkOptions
from cell.link.errors import RequestRefusedError
from cell.rapid.interp import Program
from cell.rapid.interp.rtypes import F32
from cell.sim.rapid_controller import RapidController
from cell.sim.world import SimClock

OLD = Path(__file__).parent / "rapid_modules" / "old_float32_id.mod"
HOME = np.array([0.0, -0.3, 0.4, 0.0, 0.5, 0.0])
LINK = LinkOptions(response_timeout_s=0.15, retries=40, heartbeat_period_s=0.05)
#: half the spacing of singles at 350 deg (rad): what a num joint can hold
NUM_RES_RAD = np.deg2rad(np.spacing(np.float32(350.0)))


def _wide_tour(n: int = 240) -> tuple[np.ndarray, list[int]]:
    """J1 to +-150 deg, J4 to +-200 deg, J6 to +-350 deg; stops at the extremes."""
    s = np.linspace(0.0, 1.0, n)[:, None]
    amp = np.deg2rad([150.0, 20.0, -15.0, 200.0, 30.0, 350.0])
    return HOME + np.sin(2 * np.pi * s) * amp, [n // 4, 3 * n // 4]


def _old_id(rows_udeg: np.ndarray) -> int:
    """The trajectory id of the rows (no stops) as the old module code computed it, run in the
    interpreter (``rapid_modules/old_float32_id.mod``)."""
    p = Program.from_file(OLD)
    wire = p.global_value("wire")
    data = np.asarray(rows_udeg, "<i4").tobytes()
    wire.data[: len(data)], wire.n = data, len(data)
    p.state.globals[p.scope.lookup("nRows").slot] = F32(len(rows_udeg))
    p.run("main", host=None)
    return int(p.global_value("result"))


def test_old_float32_id_refuses_wide_tours_only() -> None:
    q, _ = _wide_tour()
    wide = np.array([m.rad_to_wire(r) for r in q[::6]])[:50]
    small = np.clip(wide, -8_000_000, 8_000_000)  # within +-8 deg: integers exact in a num
    assert _old_id(small) == m.trajectory_id(small, [])
    assert _old_id(wide) != m.trajectory_id(wide, [])


@pytest.mark.parametrize("transport", ["pty", "socket"])
def test_wide_tour_loads_and_runs_in_the_module(transport: str) -> None:
    q, stops = _wide_tour()
    temps = lambda t: np.full(6, 25.0)  # noqa: E731
    with (
        RapidController(SimClock(50.0), temps, "abb_test", HOME, transport=transport) as sim,
        ControllerClient(sim.url, LINK) as c,
    ):
        traj_id = c.load_trajectory(q, stops, 0.004)
        for k, row in enumerate(stops):
            c.move_to_stop(k)
            st = c.wait_in_position(k, timeout_s=10.0)
            assert st.state == m.State.IN_POSITION and st.traj_id == traj_id
            np.testing.assert_allclose(st.q_rad, q[row], rtol=0, atol=NUM_RES_RAD)
        assert abs(np.rad2deg(q[stops[0]][5])) > 300 and abs(np.rad2deg(q[stops[1]][0])) > 149
        c.move_to_stop(len(stops))
        np.testing.assert_allclose(c.wait_in_position(len(stops), 10.0).q_rad, q[-1],
                                   rtol=0, atol=NUM_RES_RAD)  # fmt: skip
        assert sim.error is None


def test_module_refuses_rows_out_of_order() -> None:
    q, stops = _wide_tour(60)
    rows = np.array([m.rad_to_wire(r) for r in q])
    temps = lambda t: np.full(6, 25.0)  # noqa: E731
    with (
        RapidController(SimClock(50.0), temps, "abb_test", HOME) as sim,
        ControllerClient(sim.url, LINK) as c,
    ):
        tid = m.trajectory_id(rows, stops)
        c.request(m.Msg.LOAD_BEGIN, m.LOAD_BEGIN.pack(tid, len(rows), len(stops), 4000))
        with pytest.raises(RequestRefusedError, match="out of order"):
            c.request(m.Msg.LOAD_ROWS, m.pack_rows(20, rows[20:40]))
        with pytest.raises(RequestRefusedError, match="missing"):
            c.request(m.Msg.LOAD_END, m.U32.pack(tid))
        with pytest.raises(RequestRefusedError, match="too short"):
            c.request(m.Msg.LOAD_ROWS, m.pack_rows(0, rows[:20])[:100])
        assert sim.error is None
