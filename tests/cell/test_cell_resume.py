"""Resuming a stopped run with the reference rounds at their default: the arm is brought home
along the tour before the reference trajectory is loaded, and ``--reset`` clears a latched
emergency stop (the run refuses to start on one without it)."""

from __future__ import annotations

from pathlib import Path

import pytest
from cell_fixtures import SmallCell, link_for

from cell.cli import main
from cell.link.client import ControllerClient, LinkOptions
from cell.link.errors import RunFaultError
from cell.review.store import Store
from cell.run.runner import Runner, RunOptions
from cell.run.setup import resume_run, start_run
from cell.sim.camserver import CameraServer
from cell.sim.faults import FaultPlan
from cell.sim.rapid_controller import RapidController
from cell.sim.session import SimCell
from cell.sim.world import WorldOptions

FAST_LINK = LinkOptions(response_timeout_s=0.05, retries=20, heartbeat_period_s=0.1)
#: a fast clock: the default 300 s between reference rounds pass in 0.2 s
WORLD = WorldOptions(speed=1500.0)


def _runner(sc: SmallCell, run_dir: Path, sim: SimCell, resume: bool, progress=None,
            part_c: float | None = None):  # fmt: skip
    if resume:
        files = resume_run(run_dir)
    else:
        files = start_run(run_dir, sc.cell, sc.tour, "tour.json", sim.url, sc.reference)
    ctrl = "rapid" if isinstance(sim.controller, RapidController) else "python"
    client = ControllerClient(sim.url, link_for(ctrl, FAST_LINK))
    client.connect()
    options = RunOptions(settle_s=0.0, reconnect_budget_s=5.0,  # default reference rounds
                         part_temperature_c=part_c)  # fmt: skip
    runner = Runner(files.cell, files.tour, files.store, client, sim.camera, options,
                    files.reference, progress=progress)  # fmt: skip
    return runner, files, client


def _estop_while_inspecting(sim: SimCell):
    def progress(event: str, data: dict) -> None:
        if event == "state" and data["state"] == "inspecting":
            sim.controller.estop_at_stop = 1

    return progress


def test_resume_after_estop_at_a_hole_with_default_reference_rounds(
    small_cell: SmallCell, tmp_path: Path, controller_rapid_slow: str
) -> None:
    assert RunOptions().reference_rounds > 0
    with SimCell.start(small_cell.cell, WORLD, controller=controller_rapid_slow) as sim:
        runner, files, client = _runner(small_cell, tmp_path, sim, False,
                                        _estop_while_inspecting(sim), part_c=24.5)  # fmt: skip
        try:
            with pytest.raises(RunFaultError):
                runner.run()
        finally:
            client.close()
            files.store.close()
        with ControllerClient(sim.url, link_for(controller_rapid_slow, FAST_LINK)) as operator:
            operator.reset()
        runner, files, client = _runner(small_cell, tmp_path, sim, True)
        try:
            result = runner.run()
            stored = files.store.results()
            events = files.store.events()
        finally:
            client.close()
            files.store.close()
    assert result.status == "done"
    assert [r.hole_id for r in stored] == small_cell.tour.hole_order
    assert any("off home" in e["message"] for e in events)
    assert sum(e["kind"] == "state" and e["state"] == "reference" for e in events) == 2
    # the part temperature given to the first run holds for the holes the resumed run measured
    assert all("part at 24.50 degC" in r.budget["notes"][0] for r in stored if r.measured)
    assert all(r.decision in ("conforming", "inconclusive", "nonconforming") for r in stored
               if r.measured)  # fmt: skip


def _cli(sc: SmallCell, sim: SimCell, cam: CameraServer, run_dir: Path, *extra: str) -> int:
    where = ["--resume", str(run_dir)] if "--resume" in extra else [
        str(sc.tour_path), "--cell", str(sc.path), "--out", str(run_dir)]  # fmt: skip
    rest = [a for a in extra if a != "--resume"]
    return main(["run", *where, "--port", sim.url, "--camera", cam.url, "--quiet",
                 "--no-record", "--settle-s", "0", *rest])  # fmt: skip


def test_cli_refuses_a_latched_estop_and_reset_clears_it(
    small_cell: SmallCell, tmp_path: Path, capsys, controller: str
) -> None:
    run = tmp_path / "run"
    with SimCell.start(
        small_cell.cell, WORLD, FaultPlan(estop_at_stop=1), controller=controller
    ) as sim:
        cam = CameraServer(sim.camera).start()
        try:
            assert _cli(small_cell, sim, cam, run, "--reference-rounds", "0", "--yes") == 2
            assert "ESTOP" in capsys.readouterr().err
            assert _cli(small_cell, sim, cam, run, "--resume", "--yes") == 2
            err = capsys.readouterr().err
            assert "in ESTOP" in err and "--reset" in err and "Traceback" not in err
            assert _cli(small_cell, sim, cam, run, "--resume", "--reset", "--yes") == 0
        finally:
            cam.close()
    with Store.open(run) as store:
        assert store.run_info()["state"] == "done"
        assert [r.hole_id for r in store.results()] == small_cell.tour.hole_order
