"""``holecell remeasure RUN_DIR``: measure a run's kept stereo pairs again with today's code.

Every stored hole whose pair the run kept (``RUN_DIR/images``:
:mod:`cell.review.audit_images`) goes through :func:`cell.run.inspect.inspect_hole` again,
with the joints, temperatures and controller time stored with it, the thermal model it was
compensated with (by its id in the store), the run's cell calibration (``RUN_DIR/cellcal.json``,
no age limit: it is the one the run used; checked against the cell's stereo file it was made
with, its stereo extrinsics override those of ``stereo`` as in the run) and the run's part
temperature and decision rule; with the cell's stereo calibration, or a corrected one
(``stereo``). A better algorithm or a corrected stereo calibration is
applied to an old run this way.

Nothing of the original run is written: the results go into a new run directory (the same
cell, tour and planned holes; the models and the calibration copied; an event naming the
source), and its reports are written there. A hole without a kept pair keeps its stored
result, with the reason saying it was not measured again.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from cell.calibration.use import (
    RUN_FILENAME,
    RunGeometry,
    calibrated_stereo,
    load_run_calibration,
    store_calibration,
)
from cell.camera import cell_stereo
from cell.gdt.report_fields import run_cell
from cell.records.hole_result import HoleResult
from cell.review.audit_images import load_pair
from cell.review.report import write_report
from cell.review.store import Store
from cell.run.inspect import inspect_hole
from cell.run.setup import check_new_run_dir
from cell.uncertainty.context import budget_context
from cell.uncertainty.decision import DEFAULT_RULE
from cell.uncertainty.part_temperature import PartThermalState, part_state
from measure import StereoCalibration
from robots.thermal.modelfile import model_from_dict


@dataclass(frozen=True)
class Remeasured:
    """What :func:`remeasure` did: the new run directory, the holes measured again and those
    kept as stored (no pair), and per hole measured again the stored and the new result."""

    out_dir: Path
    remeasured: tuple[str, ...]
    kept: tuple[str, ...]
    pairs: tuple[tuple[HoleResult, HoleResult], ...]


def remeasure(run_dir: str | Path, out_dir: str | Path,
              stereo_path: str | Path | None = None) -> Remeasured:  # fmt: skip
    """Measure ``run_dir``'s kept pairs again into the new run directory ``out_dir``."""
    run_dir, out = Path(run_dir), Path(out_dir)
    check_new_run_dir(out, resumable=False)
    with Store.open(run_dir) as old:
        info, planned, results = old.run_info(), old.planned(), old.results()
        part_dict = old.part_state()
        models = {i: old.model(i) for i in {r.thermal_model_id for r in results} if i is not None}
    cell = run_cell(info)
    stereo = StereoCalibration.load(stereo_path) if stereo_path else cell_stereo(cell)
    arm = cell.build_arm()
    cal_path = run_dir / RUN_FILENAME
    run_cal = (load_run_calibration(cal_path, cell, cell.build_robot(), cell_stereo(cell), None)
               if cal_path.is_file() else None)  # fmt: skip
    head = calibrated_stereo(stereo, run_cal)
    target = cell.calibration_target
    geometry = RunGeometry(arm, head, run_cal, None if target is None else target.T_cell_target())
    part = PartThermalState.from_dict(part_dict) if part_dict else part_state(cell, None, None)
    rule = next((r.decision_rule for r in results if r.decision_rule), None) or DEFAULT_RULE
    context = budget_context(cell, head, part, rule)
    holes = {h.id: h for h in cell.holes_in_cell()}
    new_results, done, kept = [], [], []
    with Store.create(out, cell_name=info["cell_name"], cell_sha256=info["cell_sha256"],
                      cell_text=info["cell_text"], cell_path=info["cell_path"],
                      tour_text=info["tour_text"], reference_text=info["reference_text"],
                      robot_model=info["robot_model"], port=info["port"],
                      holes=planned) as store:  # fmt: skip
        ids = {i: store.record_model(*m) for i, m in models.items() if m is not None}
        thermal = {i: model_from_dict(json.loads(models[i][1]), f"{run_dir} (thermal model {i})")
                   for i in ids}  # fmt: skip
        store.set_part_state(part.to_dict())
        if run_cal is not None:
            store_calibration(run_cal, out)
        for r in results:
            pair = load_pair(run_dir, r.stop_index, r.hole_id)
            if pair is None:
                why = "; ".join(filter(None, [r.reason, "not measured again: no pair kept"]))
                store.record_hole(replace(r, reason=why, thermal_model_id=ids.get(
                    r.thermal_model_id)))  # fmt: skip
                kept.append(r.hole_id)
                continue
            new, _ = inspect_hole(cell, geometry, thermal.get(r.thermal_model_id), head,
                                  holes[r.hole_id], r.stop_index, pair[0], pair[1],
                                  np.asarray(r.q_rad, float), np.asarray(r.temperatures_c, float),
                                  r.sim_time_s, context)  # fmt: skip
            new = replace(new, thermal_model_id=ids.get(r.thermal_model_id))
            store.record_hole(new)
            new_results.append((r, new))
            done.append(r.hole_id)
        store.event("remeasure", f"measured again from {run_dir} ({len(done)} pairs; "
                    f"{len(kept)} holes kept as stored) with the stereo calibration "
                    f"{stereo.source}")  # fmt: skip
        store.set_state("done", finished=True)
    write_report(out)
    return Remeasured(out, tuple(done), tuple(kept), tuple(new_results))
