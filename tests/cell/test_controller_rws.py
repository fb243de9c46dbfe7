"""``holecell controller deploy`` against a simulated RWS 1.0 (digest authentication, the
order of the calls, the module really started: the uploaded text runs in the RAPID interpreter
and answers on the link), and ``holecell run --rws`` stopping a run cleanly on motors off."""

from __future__ import annotations

import socket
import time
from pathlib import Path

import pytest
from cell_fixtures import SmallCell, steady_drift

from cell.cli import main
from cell.config import load_cell
from cell.controller.deploy import MODULE_FILE
from cell.controller.rws1 import Rws1Manager
from cell.controller.watch import ControllerWatch, WatchedClient
from cell.link.client import ControllerClient
from cell.link.errors import RunFaultError
from cell.rapid.module import link_module, link_settings
from cell.review.store import Store
from cell.run.ahead import STOPS_AHEAD
from cell.run.runner import Runner, RunOptions
from cell.run.setup import start_run
from cell.sim.rapid_controller import RapidController
from cell.sim.rws_server import RwsFake
from cell.sim.session import SimCell
from cell.sim.world import SimWorld, WorldOptions

SECRET = "s3cret-Pa55"


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


class Controller:
    """The fake's RAPID: the uploaded module run by the interpreter when RWS starts it."""

    def __init__(self, tmp: Path) -> None:
        self.tmp, self.rapid = tmp, None
        self.cell = load_cell(None)

    def start(self, path: str, text: str) -> None:
        module = self.tmp / Path(path).name
        module.write_text(text)
        w = SimWorld(self.cell, WorldOptions(speed=5.0))
        self.rapid = RapidController(w.clock, w.temperatures, self.cell.robot.model,
                                     self.cell.home_q(), transport="socket",
                                     module=module).start()  # fmt: skip

    def close(self) -> None:
        if self.rapid is not None:
            self.rapid.close()


def test_deploy_uploads_loads_resets_starts_and_the_module_answers(
    tmp_path: Path, capsys, monkeypatch
) -> None:
    port = f"socket://127.0.0.1:{_free_port()}"
    ctrl = Controller(tmp_path)
    monkeypatch.setenv("HOLECELL_RWS_PASSWORD", SECRET)
    try:
        with RwsFake(password=SECRET, on_start=ctrl.start) as rws:
            code = main(["controller", "deploy", "--rws", rws.url, "--port", port])
            out = capsys.readouterr()
            assert code == 0, out.err
            steps = [(m, p, a) for m, p, a in rws.calls if m != "GET"]
    finally:
        ctrl.close()
    assert rws.unauthorized >= 1 and not rws.refused  # challenged once, then digest + cookie
    order = [("PUT", f"/fileservice/hd0a/RAMDISK/{MODULE_FILE}", ""),
             ("POST", "/rw/mastership", "request"), ("POST", "/rw/rapid/tasks/T_ROB1", "loadmod"),
             ("POST", "/rw/mastership", "release"), ("POST", "/rw/mastership", "request"),
             ("POST", "/rw/rapid/execution", "resetpp"), ("POST", "/rw/mastership", "release"),
             ("POST", "/rw/rapid/execution", "start")]  # fmt: skip
    assert steps == order
    expected = link_module(link_settings(ctrl.cell.robot.model, port))
    assert rws.files[f"/hd0a/RAMDISK/{MODULE_FILE}"].decode() == expected
    assert "upload -> loadmod -> resetpp -> start -> link" in out.out
    assert "holecell-sim-rapid" in out.out  # the interpreted module answered on that port
    assert SECRET not in out.out + out.err


def test_a_wrong_password_is_one_line_without_the_password(tmp_path: Path, capsys) -> None:
    with RwsFake(password=SECRET) as rws:
        code = main(["controller", "deploy", "--rws", rws.url, "--port", "socket://127.0.0.1:1",
                     "--password", "wrong-guess"])  # fmt: skip
    err = capsys.readouterr().err
    assert code == 2 and "authentication refused" in err and "Traceback" not in err
    assert "wrong-guess" not in err and not rws.files


def test_deploy_refuses_motors_off(capsys) -> None:
    with RwsFake() as rws:
        rws.ctrlstate = "motoroff"
        code = main(["controller", "deploy", "--rws", rws.url, "--port", "socket://127.0.0.1:1"])
    err = capsys.readouterr().err
    assert code == 2 and "motors are off (controller state motoroff" in err
    assert not rws.files


def test_a_run_watched_over_rws_stops_cleanly_when_the_motors_go_off(
    small_cell: SmallCell, tmp_path: Path
) -> None:
    world = WorldOptions(speed=50.0, drift=steady_drift())
    with SimCell.start(small_cell.cell, world) as sim, RwsFake() as rws:
        rws.execution = "running"
        watch = ControllerWatch(Rws1Manager(rws.url, "Default User", "robotics"), 0.05)
        client = WatchedClient(ControllerClient(sim.url), watch.start())
        files = start_run(tmp_path, small_cell.cell, small_cell.tour, "tour.json", sim.url)

        def progress(event: str, data: dict) -> None:
            if event == "hole" and data["stop"] == 0:
                rws.ctrlstate = "motoroff"  # the operator switches the motors off
                t_end = time.monotonic() + 30.0
                while watch.problem is None and time.monotonic() < t_end:
                    time.sleep(0.01)

        client.connect()
        try:
            options = RunOptions(settle_s=0.0, reference_rounds=0)
            with pytest.raises(RunFaultError, match="motors off"):
                Runner(files.cell, files.tour, files.store, client, sim.camera, options,
                       progress=progress).run()  # fmt: skip
        finally:
            client.close()
            files.store.close()
    with Store.open(tmp_path) as store:
        info, n = store.run_info(), len(store.stored_ids())
    # stop 0 is reported once the arm is at stop STOPS_AHEAD and has captured it
    # (cell.run.ahead): the motors go off then, the next move fails, and every captured stop is
    # stored
    assert info["state"] == "fault" and n == STOPS_AHEAD + 1
    msg = store_message(tmp_path)
    assert "motors off (controller state motoroff)" in msg and "motoroff, execution" in msg


def store_message(run_dir: Path) -> str:
    with Store.open(run_dir) as store:
        return store.events()[-1]["message"]


def test_holecell_run_with_rws_refuses_a_controller_not_running_rapid(
    small_cell: SmallCell, tmp_path: Path, capsys, monkeypatch
) -> None:
    monkeypatch.setenv("HOLECELL_RWS_PASSWORD", SECRET)
    with SimCell.start(small_cell.cell) as sim, RwsFake(password=SECRET) as rws:
        code = main(["run", str(small_cell.tour_path), "--cell", str(small_cell.path),
                     "--port", sim.url, "--camera", "tcp://127.0.0.1:1", "--rws", rws.url,
                     "--out", str(tmp_path / "run"), "--yes", "--quiet"])  # fmt: skip
    err = capsys.readouterr().err
    assert code == 2 and "RAPID execution stopped" in err and SECRET not in err
    assert rws.unauthorized >= 1 and not (tmp_path / "run").exists()
