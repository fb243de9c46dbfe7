"""``holecell survey`` end to end on the simulated cell: the survey tour planned and driven, the
markers rendered, detected and identified in both images, one adjustment, ``markers.json``
against the simulator's true markers; and a run referenced by it."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from referencing_cells import small_cell_text

from cell.cli import main
from cell.config import load_cell
from cell.referencing import load_markers
from cell.referencing.survey.gauge import rigid_fit
from cell.sim.camserver import CameraServer
from cell.sim.session import SimCell
from cell.sim.truth import CellTruth
from cell.sim.world import WorldOptions


@pytest.mark.slow
def test_holecell_survey_measures_the_true_markers(tmp_path: Path, capsys) -> None:
    path = tmp_path / "small.yaml"
    path.write_text(small_cell_text())
    cell = load_cell(path)
    truth = CellTruth.drawn(2, cell)
    out = tmp_path / "markers.json"
    with SimCell.start(cell, WorldOptions(speed=50.0, truth=truth)) as sim:
        cam = CameraServer(sim.camera).start()
        try:
            code = main(["survey", str(path), "--port", sim.url, "--camera", cam.url, "-o",
                         str(out), "--settle-s", "0", "--quiet"])  # fmt: skip
        finally:
            cam.close()
        true = sim.world.markers
    printed = capsys.readouterr().out
    assert code == 0, printed
    for figure in ("markers from", "px RMS", "robot time", "adjustment", "wrote"):
        assert figure in printed
    _doc, ids, P, _C = load_markers(out)
    T = true.true[[true.ids.index(m) for m in ids]]
    F = rigid_fit(P, T)
    e = np.linalg.norm(P @ F[:3, :3].T + F[:3, 3] - T, axis=1)
    assert np.sqrt(np.mean(e**2)) < 10e-6 and e.max() < 25e-6, (e.mean(), e.max())
