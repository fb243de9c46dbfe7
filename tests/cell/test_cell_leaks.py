"""Nothing is left open when opening or starting fails: the store's connections, the simulated
controller's thread and port."""

from __future__ import annotations

import sqlite3
import threading
from pathlib import Path

import pytest
from cell_fixtures import SmallCell

import cell.review.store as store_mod
import cell.sim.session as session
from cell.errors import CellError
from cell.review.store import Store, StoreError
from cell.run.setup import resume_run, start_run
from cell.sim.controller import SimController
from cell.sim.server import SimServer
from cell.sim.world import SimWorld


@pytest.fixture
def connections(monkeypatch) -> list[sqlite3.Connection]:
    """Every connection the store module opens."""
    opened: list[sqlite3.Connection] = []
    real = sqlite3.connect

    def connect(*args, **kwargs):
        con = real(*args, **kwargs)
        opened.append(con)
        return con

    monkeypatch.setattr(store_mod.sqlite3, "connect", connect)
    return opened


def _all_closed(cons: list[sqlite3.Connection]) -> bool:
    for con in cons:
        try:
            con.execute("SELECT 1")
        except sqlite3.ProgrammingError:
            continue
        return False
    return True


def test_store_open_closes_on_foreign_schema(tmp_path: Path, connections) -> None:
    con = sqlite3.connect(tmp_path / "results.sqlite")
    con.execute("CREATE TABLE meta (key TEXT, value TEXT)")
    con.execute("INSERT INTO meta VALUES ('schema_version', '99')")
    con.commit()
    con.close()
    with pytest.raises(StoreError, match="schema version '99'"):
        Store.open(tmp_path)
    assert connections and _all_closed(connections)


def test_resume_closes_the_store_when_the_tour_is_refused(
    small_cell: SmallCell, tmp_path: Path, connections
) -> None:
    start_run(tmp_path, small_cell.cell, small_cell.tour, "tour.json", "p").store.close()
    d = small_cell.tour.to_dict()
    d["stops"].append(d["stops"][0])
    con = sqlite3.connect(tmp_path / "results.sqlite")
    with con:
        con.execute("UPDATE run SET tour_text = ?", (__import__("json").dumps(d),))
    con.close()
    with pytest.raises(CellError, match="more than once"):
        resume_run(tmp_path)
    assert _all_closed(connections)


def _sim_threads() -> int:
    return sum(t.name == "holecell-sim" and t.is_alive() for t in threading.enumerate())


def test_sim_start_stops_the_server_when_the_camera_fails(small_cell: SmallCell,
                                                          monkeypatch) -> None:  # fmt: skip
    def broken(*args, **kwargs):
        raise CellError("no stereo calibration")

    monkeypatch.setattr(session, "SimCamera", broken)
    before = _sim_threads()
    with pytest.raises(CellError, match="no stereo"):
        session.SimCell.start(small_cell.cell)
    assert _sim_threads() == before


@pytest.mark.parametrize("transport", ["pty", "socket"])
def test_sim_server_close_twice(small_cell: SmallCell, transport: str) -> None:
    w = SimWorld(small_cell.cell)
    ctrl = SimController(w.clock, w.temperatures, "m", small_cell.cell.home_q())
    server = SimServer(ctrl, transport=transport).start()
    server.close()
    server.close()


def test_cli_resume_with_a_dead_port_closes_the_store(
    small_cell: SmallCell, tmp_path: Path, connections, capsys, monkeypatch
) -> None:
    from cell.cli import main
    from cell.link.client import ControllerClient
    from cell.link.errors import LinkError

    def dead(self):
        raise LinkError(self.url, "cannot open the port")

    monkeypatch.setattr(ControllerClient, "connect", dead)
    start_run(tmp_path, small_cell.cell, small_cell.tour, "tour.json", "p").store.close()
    code = main(["run", "--resume", str(tmp_path), "--port", str(tmp_path / "no-such-port"),
                 "--camera", "tcp://127.0.0.1:1"])  # fmt: skip
    assert code == 2 and "no-such-port" in capsys.readouterr().err
    assert len(connections) > 1 and _all_closed(connections)
