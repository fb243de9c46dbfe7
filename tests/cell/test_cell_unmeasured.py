"""A hole that was seen but could not be measured is ``unmeasured`` (not ``missing``), counted
apart, and tried again by a resumed run (the earlier attempt kept as an event)."""

from __future__ import annotations

from pathlib import Path

from cell_fixtures import SmallCell, steady_drift

import cell.run.inspect as ih
from cell.link.client import ControllerClient, LinkOptions
from cell.review.report import summary
from cell.run.runner import Runner, RunOptions
from cell.run.setup import resume_run, start_run
from cell.sim.session import SimCell
from cell.sim.world import WorldOptions
from measure.errors import FitError

FAST_LINK = LinkOptions(response_timeout_s=0.05, retries=20, heartbeat_period_s=0.1)


def _run(sc: SmallCell, run_dir: Path, sim: SimCell, resume: bool):
    if resume:
        files = resume_run(run_dir)
    else:
        files = start_run(run_dir, sc.cell, sc.tour, "tour.json", sim.url)
    options = RunOptions(settle_s=0.0, reference_rounds=0)
    try:
        with ControllerClient(sim.url, FAST_LINK) as client:
            result = Runner(files.cell, files.tour, files.store, client, sim.camera,
                            options).run()  # fmt: skip
        return result, files.store.results(), summary(files.store), files.store.events()
    finally:
        files.store.close()


def test_unmeasured_hole_is_counted_and_retried(small_cell: SmallCell, tmp_path: Path,
                                                monkeypatch) -> None:  # fmt: skip
    real, calls = ih.measure_hole, []

    def flaky(*args, **kwargs):
        calls.append(1)
        if len(calls) == 2:  # the second hole of the first run
            raise FitError("the circle fit did not converge")
        return real(*args, **kwargs)

    monkeypatch.setattr(ih, "measure_hole", flaky)
    bad = small_cell.tour.hole_order[1]
    with SimCell.start(small_cell.cell, WorldOptions(speed=50.0, drift=steady_drift())) as sim:
        _, stored, summ, _ = _run(small_cell, tmp_path, sim, False)
        by_id = {r.hole_id: r for r in stored}
        assert by_id[bad].status == "unmeasured" and "not measurable" in by_id[bad].reason
        assert summ["holes_unmeasured"] == 1 and summ["holes_missing"] == 0
        result, stored, summ, events = _run(small_cell, tmp_path, sim, True)
    assert [r.hole_id for r in result.stored] == [bad]
    assert {r.status for r in stored} == {"ok"} and len(stored) == len(small_cell.tour.stops)
    assert summ["holes_unmeasured"] == 0
    retry = [e for e in events if e["kind"] == "retry"]
    assert len(retry) == 1 and retry[0]["data"]["status"] == "unmeasured"
