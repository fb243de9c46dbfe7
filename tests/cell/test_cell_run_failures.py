"""Whatever stops a run (a camera error, an operator interrupt) stops the arm, leaves the run
state with its reason in the store, and the CLI still writes the report; bad numbers are
refused by the argument parser."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from cell_fixtures import SmallCell, link_for, steady_drift

from cell.camera import CameraError
from cell.cli import main
from cell.link import messages as m
from cell.link.client import ControllerClient, LinkOptions
from cell.link.errors import RunFaultError
from cell.review.store import Store
from cell.run.runner import Runner, RunOptions
from cell.run.setup import start_run
from cell.sim.camserver import CameraServer
from cell.sim.rapid_controller import RapidController
from cell.sim.session import SimCell
from cell.sim.world import WorldOptions

FAST_LINK = LinkOptions(response_timeout_s=0.05, retries=20, heartbeat_period_s=0.1)
WORLD = WorldOptions(speed=50.0, drift=steady_drift())


def _fail_on_capture(sim: SimCell, n_ok: int) -> None:
    """Make the simulated head fail after ``n_ok`` good captures (or snapshots: the runner
    renders the simulated head's pairs in a worker)."""
    calls = []

    def failing(real):
        def trigger():
            calls.append(1)
            if len(calls) > n_ok:
                raise CameraError("sim head", "the strobe did not fire")
            return real()

        return trigger

    sim.camera.capture = failing(sim.camera.capture)
    sim.camera.snapshot = failing(sim.camera.snapshot)


def _run(sc: SmallCell, run_dir: Path, sim: SimCell, progress=None) -> None:
    files = start_run(run_dir, sc.cell, sc.tour, "tour.json", sim.url)
    ctrl = "rapid" if isinstance(sim.controller, RapidController) else "python"
    client = ControllerClient(sim.url, link_for(ctrl, FAST_LINK))
    client.connect()
    options = RunOptions(settle_s=0.0, reference_rounds=0)
    try:
        Runner(files.cell, files.tour, files.store, client, sim.camera, options,
               progress=progress).run()  # fmt: skip
    finally:
        client.close()
        files.store.close()


def _state(run_dir: Path) -> tuple[str, str, int]:
    with Store.open(run_dir) as store:
        info, events = store.run_info(), store.events()
        return info["state"], events[-1]["message"], len(store.stored_ids())


def test_camera_error_leaves_a_fault_record(
    small_cell: SmallCell, tmp_path: Path, controller: str
) -> None:
    with SimCell.start(small_cell.cell, WORLD, controller=controller) as sim:
        _fail_on_capture(sim, 1)
        with pytest.raises(CameraError):
            _run(small_cell, tmp_path, sim)
        assert sim.controller.s.state != m.State.MOVING
    state, message, n_stored = _state(tmp_path)
    assert state == "fault" and "CameraError" in message and "strobe" in message
    assert n_stored == 1


def test_interrupt_stops_the_run(
    small_cell: SmallCell, tmp_path: Path, controller_rapid_slow: str
) -> None:
    def progress(event: str, data: dict) -> None:
        if event == "hole":
            raise KeyboardInterrupt

    with (
        SimCell.start(small_cell.cell, WORLD, controller=controller_rapid_slow) as sim,
        pytest.raises(KeyboardInterrupt),
    ):
        _run(small_cell, tmp_path, sim, progress)
    state, message, n_stored = _state(tmp_path)
    assert state == "stopped" and "interrupted" in message and n_stored == 1


def test_cli_writes_the_report_of_a_failed_run(
    small_cell: SmallCell, tmp_path: Path, capsys, controller_rapid_slow: str
) -> None:
    run = tmp_path / "run"
    with SimCell.start(small_cell.cell, WORLD, controller=controller_rapid_slow) as sim:
        _fail_on_capture(sim, 1)
        with CameraServer(sim.camera).start() as cam:
            code = main(["run", str(small_cell.tour_path), "--cell", str(small_cell.path),
                         "--port", sim.url, "--camera", cam.url, "--out", str(run), "--yes",
                         "--quiet", "--no-record", "--settle-s", "0",
                         "--reference-rounds", "0"])  # fmt: skip
    err = capsys.readouterr().err
    assert code == 2 and "strobe" in err and "Traceback" not in err
    doc = json.loads((run / "report.json").read_text())
    assert doc["summary"]["state"] == "fault" and doc["summary"]["holes_stored"] == 1


@pytest.mark.parametrize(("option", "value"), [("--settle-s", "-0.1"), ("--settle-s", "nan"),
                                               ("--reference-rounds", "-1")])  # fmt: skip
def test_cli_refuses_negative_numbers(small_cell: SmallCell, capsys, option, value) -> None:
    with pytest.raises(SystemExit) as exc:
        main(["run", str(small_cell.tour_path), "--cell", str(small_cell.path), "--port", "x",
              "--camera", "tcp://x:1", option, value])  # fmt: skip
    assert exc.value.code == 2 and option in capsys.readouterr().err


def test_move_timeout_is_a_fault_not_a_dead_link(
    small_cell: SmallCell, tmp_path: Path, controller: str
) -> None:
    """A slow arm (the simulation at a tenth of real time) misses the move timeout: the run
    stops the arm and faults at once, without reconnecting or reloading the trajectory."""
    files = start_run(tmp_path, small_cell.cell, small_cell.tour, "tour.json", "sim")
    slow = WorldOptions(speed=0.1, drift=steady_drift())
    with (
        SimCell.start(small_cell.cell, slow, controller=controller) as sim,
        ControllerClient(sim.url, link_for(controller, FAST_LINK)) as c,
    ):
        options = RunOptions(settle_s=0.0, reference_rounds=0, move_timeout_s=0.3)
        runner = Runner(files.cell, files.tour, files.store, c, sim.camera, options)
        try:
            with pytest.raises(RunFaultError, match="move timed out"):
                runner.run()
            assert sim.controller.s.state == m.State.STOPPED
            assert c.stats.reconnects == 0
            events = files.store.events()
        finally:
            files.store.close()
    assert not any(e["kind"] == "link" for e in events)
    assert events[-1]["state"] == "fault"


def test_tour_with_a_repeated_stop_is_refused(small_cell: SmallCell, tmp_path: Path,
                                              capsys) -> None:  # fmt: skip
    d = json.loads(small_cell.tour_path.read_text())
    d["stops"].append(d["stops"][0])
    bad = tmp_path / "twice.json"
    bad.write_text(json.dumps(d))
    run = tmp_path / "run"
    code = main(["run", str(bad), "--cell", str(small_cell.path), "--port", "/dev/null",
                 "--camera", "tcp://127.0.0.1:1", "--out", str(run)])  # fmt: skip
    err = capsys.readouterr().err
    assert code == 2 and "twice.json" in err and "stops[].hole_id" in err, err
    assert d["stops"][0]["hole_id"] in err and not run.exists()
