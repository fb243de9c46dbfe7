"""``holecell demo`` shows a bar for every stage that takes seconds (issue 26, finding 6): the
cell calibration's views (captured and detected, of the tour's) and its solve, with an ETA,
as the planner's and the hole tour's bars do."""

from __future__ import annotations

import gc
import io
from pathlib import Path

from cell_fixtures import SmallCell

from cell.calibration.plan import CalibrationPlanOptions, cell_target, plan_calibration
from cell.camera import cell_stereo
from cell.commands.plan_cmd import StageBars
from cell.config.tours import hole_stops
from cell.demo.calibrate import calibrate_demo_cell_images
from cell.sim.session import SimCell
from cell.sim.truth import CellTruth
from cell.sim.world import WorldOptions
from planner import Options
from planner.calibration import CandidateOptions


def test_a_stage_bar_shows_its_eta_until_done() -> None:
    out = io.StringIO()
    bars = StageBars(out)
    bars.tty = True  # drawn in place, as on a terminal
    bars("calibration", 3, 12)
    assert "calibration" in out.getvalue() and "3/12" in out.getvalue()
    assert "ETA" in out.getvalue()
    bars("calibration", 12, 12)
    assert out.getvalue().endswith("\n") and "ETA" not in out.getvalue().splitlines()[-1]


def test_the_demo_calibration_reports_its_views_and_solve(
    small_cell: SmallCell, tmp_path: Path
) -> None:
    cell = small_cell.cell
    cand = CandidateOptions(tilts_deg=(0.0, 20.0, 35.0), azimuths=4, roll_step_deg=90.0)
    o = CalibrationPlanOptions(views=12, criterion="geometric", predict=False, candidates=cand,
                               tour=Options(seed=0))  # fmt: skip
    caltour = plan_calibration(cell, cell_target(cell), cell_stereo(cell), hole_stops(cell)[1], o)
    gc.collect()
    seen: list[tuple[str, int, int]] = []
    world = WorldOptions(speed=20.0, drift_offset_s=1e6, truth=CellTruth.zero(0))
    with SimCell.start(cell, world) as sim:
        cal = calibrate_demo_cell_images(sim, cell, caltour, tmp_path, 20.0,
                                         lambda *a: seen.append(a))  # fmt: skip
    assert cal.path.is_file()
    views = [s for s in seen if s[0] == "calibration"]
    assert views == [("calibration", k, 12) for k in range(1, 13)]
    assert [s for s in seen if s[0] == "solve"] == [("solve", 0, 1), ("solve", 1, 1)]
    assert seen.index(("solve", 0, 1)) > seen.index(("calibration", 12, 12))
