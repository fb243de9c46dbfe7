"""The runner on the simulated cell: every hole measured once and accurately, missing holes,
emergency stop and resume, bad files refused."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from cell_fixtures import SmallCell, link_for, steady_drift

from cell.demo.demo import truth_error
from cell.errors import TourMismatchError
from cell.link.client import ControllerClient, LinkOptions
from cell.link.errors import RunFaultError
from cell.review.store import Store
from cell.run.runner import Runner, RunOptions
from cell.run.setup import resume_run, start_run
from cell.sim.faults import FaultPlan
from cell.sim.rapid_controller import RapidController
from cell.sim.session import SimCell
from cell.sim.world import WorldOptions

FAST_LINK = LinkOptions(response_timeout_s=0.05, retries=20, heartbeat_period_s=0.1)


def _run(sc: SmallCell, run_dir: Path, sim: SimCell, resume: bool = False, **opts):
    ctrl = "rapid" if isinstance(sim.controller, RapidController) else "python"
    files = (
        resume_run(run_dir)
        if resume
        else start_run(run_dir, sc.cell, sc.tour, "tour.json", sim.url, sc.reference)
    )
    client = ControllerClient(sim.url, link_for(ctrl, FAST_LINK))
    client.connect()
    options = RunOptions(
        settle_s=0.0,
        reference_rounds=opts.pop("rounds", 0),
        reference_interval_s=opts.pop("interval_s", 600.0),
        reconnect_budget_s=5.0,
    )
    runner = Runner(
        files.cell, files.tour, files.store, client, sim.camera, options, files.reference, **opts
    )
    try:
        return runner.run(), files.store.results(), files.store.events()
    finally:
        client.close()
        files.store.close()  # fmt: skip


def test_every_hole_measured_once_and_accurately(
    small_cell: SmallCell, tmp_path: Path, controller: str
) -> None:
    world = WorldOptions(speed=20.0, drift=steady_drift())
    with SimCell.start(small_cell.cell, world, controller=controller) as sim:
        result, stored, events = _run(small_cell, tmp_path, sim)
        err = truth_error(sim.world, stored)
    assert result.status == "done"
    assert [r.hole_id for r in stored] == small_cell.tour.hole_order
    assert all(r.status == "ok" for r in stored)
    assert err.n == len(stored) and err.max_m < 10e-6 and err.diameter_rms_m < 5e-6
    states = [e["state"] for e in events if e["kind"] == "state"]
    assert states == ["waiting", "inspecting", "homing", "done"]


def test_thermal_update_from_reference_rounds(
    small_cell: SmallCell, tmp_path: Path, controller_rapid_slow: str
) -> None:
    # the clock runs fast from the reference phase on, not while the run is set up: at 1500x a
    # few tenths of a second of set-up (under load) were minutes of warm-up before the cold state
    # is read, an offset of the reference temperatures no reference observation can see
    world = WorldOptions(speed=1.0, drift_offset_s=0.0)
    with SimCell.start(small_cell.cell, world, controller=controller_rapid_slow) as sim:

        def fast_from_reference(event: str, data: dict) -> None:
            # from the first round on: the cold state is read once the reference tour is
            # loaded, which takes the interpreted module seconds (hours at 1500x)
            if event == "round" and data.get("round") == 0:
                sim.world.clock.set_speed(1500.0)

        result, stored, _ = _run(small_cell, tmp_path, sim, rounds=3, progress=fast_from_reference)
        err = truth_error(sim.world, stored)
    assert "identified" in result.thermal
    assert err.rms_m < 0.2 * err.rms_uncompensated_m


def test_missing_hole_is_recorded_not_measured(
    small_cell: SmallCell, tmp_path: Path, controller_rapid_slow: str
) -> None:
    gone = small_cell.tour.hole_order[1]
    faults = FaultPlan(missing_holes=(gone,))
    world = WorldOptions(speed=20.0, drift=steady_drift())
    with SimCell.start(small_cell.cell, world, faults, controller=controller_rapid_slow) as sim:
        _, stored, _ = _run(small_cell, tmp_path, sim)
    by_id = {r.hole_id: r for r in stored}
    assert by_id[gone].status == "missing" and by_id[gone].center_part_m is None
    assert "no hole found" in by_id[gone].reason
    assert sum(r.status == "ok" for r in stored) == len(stored) - 1


def test_estop_stops_the_run_and_resume_completes(
    small_cell: SmallCell, tmp_path: Path, controller: str
) -> None:
    faults = FaultPlan(estop_at_stop=1)
    with SimCell.start(
        small_cell.cell, WorldOptions(speed=20.0), faults, controller=controller
    ) as sim:
        with pytest.raises(RunFaultError, match="ESTOP"):
            _run(small_cell, tmp_path, sim)
        with Store.open(tmp_path) as store:
            assert store.stored_ids() == {small_cell.tour.hole_order[0]}
            assert store.run_info()["state"] == "fault"
        with ControllerClient(sim.url, link_for(controller, FAST_LINK)) as operator:
            operator.reset()  # the fault is cleared at the cell
        result, stored, _ = _run(small_cell, tmp_path, sim, resume=True)
    assert result.skipped == [small_cell.tour.hole_order[0]]
    assert [r.hole_id for r in stored] == small_cell.tour.hole_order


def test_estop_during_the_reference_rounds_resumes(
    small_cell: SmallCell, tmp_path: Path, controller_rapid_slow: str
) -> None:
    # the arm stops on the reference trajectory: the resumed run goes home along that one
    faults = FaultPlan(estop_at_stop=1)
    with SimCell.start(
        small_cell.cell, WorldOptions(speed=20.0), faults, controller=controller_rapid_slow
    ) as sim:
        with pytest.raises(RunFaultError, match="reference"):
            _run(small_cell, tmp_path, sim, rounds=2, interval_s=60.0)
        with ControllerClient(sim.url, link_for(controller_rapid_slow, FAST_LINK)) as operator:
            operator.reset()
        sim.controller.estop_at_stop = None
        result, stored, events = _run(
            small_cell, tmp_path, sim, resume=True, rounds=2, interval_s=60.0
        )
    assert result.status == "done"
    assert [r.hole_id for r in stored] == small_cell.tour.hole_order
    assert any("along the reference tour" in e.get("message", "") for e in events)


def test_tour_for_another_cell_is_refused(small_cell: SmallCell, tmp_path: Path) -> None:
    other = small_cell.cell.model_copy(update={"name": "other_frame"})
    with pytest.raises(TourMismatchError, match="other_frame"):
        start_run(tmp_path, other, small_cell.tour, "tour.json", "/dev/null")
    assert not (tmp_path / "results.sqlite").exists()


def test_tour_for_another_robot_is_refused(small_cell: SmallCell, tmp_path: Path) -> None:
    d = small_cell.tour.to_dict()
    d["robot"]["model"] = "abb_irb4600_60_205"
    from planner.tour import tour_from_dict

    with pytest.raises(TourMismatchError, match="robot model"):
        start_run(tmp_path, small_cell.cell, tour_from_dict(d), "tour.json", "/dev/null")


def test_cli_refuses_truncated_tour_and_corrupt_store(
    small_cell: SmallCell, tmp_path: Path, capsys: pytest.CaptureFixture
) -> None:
    from cell.cli import main

    text = small_cell.tour_path.read_text()
    bad = tmp_path / "truncated.json"
    bad.write_text(text[: len(text) // 2])
    code = main(["run", str(bad), "--cell", str(small_cell.path), "--port", "/dev/null",
                 "--camera", "tcp://127.0.0.1:1", "--out", str(tmp_path / "run")])  # fmt: skip
    err = capsys.readouterr().err
    assert code == 2 and "truncated.json" in err and "Traceback" not in err
    run = tmp_path / "corrupt"
    run.mkdir()
    (run / "results.sqlite").write_bytes(b"\x00garbage" * 500)
    code = main(["run", "--resume", str(run), "--port", "/dev/null", "--camera", "tcp://x:1"])
    err = capsys.readouterr().err
    assert code == 2 and "results.sqlite" in err and "not modified" in err
    assert (run / "results.sqlite").read_bytes() == b"\x00garbage" * 500


def test_stored_result_matches_report(
    small_cell: SmallCell, tmp_path: Path, controller_rapid_slow: str
) -> None:
    from cell.review.report import write_report

    with SimCell.start(
        small_cell.cell,
        WorldOptions(speed=20.0, drift=steady_drift()),
        controller=controller_rapid_slow,
    ) as sim:
        _, stored, _ = _run(small_cell, tmp_path, sim)
    summ = write_report(tmp_path)
    doc = json.loads((tmp_path / "report.json").read_text())
    assert summ["holes_measured"] == len(stored) == len(doc["holes"])
    for row, r in zip(doc["holes"], stored, strict=True):
        assert np.allclose([row["measured_x_m"], row["measured_y_m"], row["measured_z_m"]],
                           r.center_part_m)  # fmt: skip
