"""The run's thermal state lives in its store: every reference observation, every model used,
and which model each hole was compensated with; a resumed run continues with them."""

from __future__ import annotations

import json
from pathlib import Path

from cell_fixtures import SmallCell

from cell.link.client import ControllerClient, LinkOptions
from cell.review.report import write_report
from cell.review.store import Store
from cell.run.runner import Runner, RunOptions
from cell.run.setup import resume_run, start_run
from cell.sim.session import SimCell
from cell.sim.world import WorldOptions

FAST_LINK = LinkOptions(response_timeout_s=0.05, retries=20, heartbeat_period_s=0.1)


def _run(sc: SmallCell, run_dir: Path, sim: SimCell, rounds: int, resume: bool, progress=None):
    if resume:
        files = resume_run(run_dir)
    else:
        files = start_run(run_dir, sc.cell, sc.tour, "tour.json", sim.url, sc.reference)
    options = RunOptions(settle_s=0.0, reference_rounds=rounds)
    try:
        with ControllerClient(sim.url, FAST_LINK) as client:
            return Runner(files.cell, files.tour, files.store, client, sim.camera, options,
                          files.reference, progress=progress).run()  # fmt: skip
    finally:
        files.store.close()


def _stop_after_first_hole(event: str, data: dict) -> None:
    if event == "hole":
        raise KeyboardInterrupt


def _interrupted(sc: SmallCell, run_dir: Path, sim: SimCell, rounds: int, resume: bool) -> None:
    try:
        _run(sc, run_dir, sim, rounds, resume, _stop_after_first_hole)
    except KeyboardInterrupt:
        return
    raise AssertionError("the run was not interrupted")


def test_observations_and_model_are_stored_and_reloaded(
    small_cell: SmallCell, tmp_path: Path
) -> None:
    with SimCell.start(small_cell.cell, WorldOptions(speed=1500.0, drift_offset_s=0.0)) as sim:
        _interrupted(small_cell, tmp_path, sim, 2, False)
        with Store.open(tmp_path) as store:
            n_obs = len(store.reference_observations())
            model_id, source, text = store.latest_model()
            cold = store.thermal_reference()
        # the reference is the cold state: the readings as the first round started
        assert cold is not None and len(cold) == 6
        assert json.loads(text)["sensors"]["reference_degC"] == list(cold)
        assert n_obs >= 2 * len(small_cell.reference.stops) - 2
        assert "identified" in source and json.loads(text)["format"] == "holecell.thermal"
        # resumed without reference rounds: the stored model compensates the next hole
        _interrupted(small_cell, tmp_path, sim, 0, True)
        # one more round: identified from the stored rows and the new ones together
        result = _run(small_cell, tmp_path, sim, 1, True)
    assert result.status == "done"
    with Store.open(tmp_path) as store:
        obs = store.reference_observations()
        used = [r.thermal_model_id for r in store.results()]
        last_id, _, store_text = store.latest_model()
    assert sorted({r[5] for r in obs}) == [0, 1, 2]
    assert json.loads(store_text)["sensors"]["reference_degC"] == list(cold)
    assert f"identified from {len(obs)} rows" in result.thermal
    assert used == [model_id, model_id, last_id] and last_id != model_id
    rows = write_report(tmp_path) and json.loads((tmp_path / "report.json").read_text())["holes"]
    assert [row["thermal_model_id"] for row in rows] == used


def test_given_model_sets_the_cold_state_of_a_warm_arm(small_cell: SmallCell, tmp_path: Path):
    """A run that starts on an arm already warm (half an hour into its warm-up) with a --thermal
    model identifies relative to that model's reference temperatures (the cold state it knows),
    not the warm readings of its first round, and so still compensates the whole warm-up (taking
    the warm readings as reference leaves most of the drift: a ratio near 1)."""
    from cell.demo.demo import truth_error
    from cell.run.thermal_update import sensor_spec
    from robots.thermal.model import ThermalModel

    arm = small_cell.cell.build_arm()
    given = ThermalModel(arm.dh, sensor_spec(6, 20.0), {}, robot_model=small_cell.cell.robot.model,
                         T_cell_base=arm.T_cell_base, T_tool0_tcp=arm.T_tool0_tcp)  # fmt: skip
    world = WorldOptions(speed=1500.0, drift_offset_s=1800.0)
    with SimCell.start(small_cell.cell, world) as sim:
        files = start_run(tmp_path, small_cell.cell, small_cell.tour, "t", sim.url,
                          small_cell.reference)  # fmt: skip
        options = RunOptions(settle_s=0.0, reference_rounds=3, reference_interval_s=600.0)
        try:
            with ControllerClient(sim.url, FAST_LINK) as client:
                result = Runner(files.cell, files.tour, files.store, client, sim.camera, options,
                                files.reference, given).run()  # fmt: skip
            err = truth_error(sim.world, files.store.results())
            assert files.store.thermal_reference() == (20.0,) * 6
        finally:
            files.store.close()
    assert "identified" in result.thermal
    assert err.rms_m < 0.4 * err.rms_uncompensated_m
