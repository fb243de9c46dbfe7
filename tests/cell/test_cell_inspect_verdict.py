"""The pass/fail verdict of one hole comes from its deviations, whatever the measurement's
quality flag: a suspect hole out of tolerance is a failed hole in the results and the report."""

from __future__ import annotations

import csv
import dataclasses
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
from cell_fixtures import SmallCell

import cell.run.inspect as ih
from cell.camera import cell_stereo
from cell.records.hole_result import HoleResult
from cell.review.report import summary, write_report
from cell.run.setup import start_run
from measure import head_frame
from robots.transforms import invert


def _inspect(sc: SmallCell, monkeypatch, status: str, offset_m: float) -> HoleResult:
    """Inspect the first stop's hole with a measurement ``offset_m`` off its nominal centre."""
    cell, stop = sc.cell, sc.tour.stops[0]
    arm = cell.build_arm()
    stereo = cell_stereo(cell)
    hole = {h.id: h for h in cell.holes_in_cell()}[stop.hole_id]
    hole = dataclasses.replace(hole, tolerance_m=50e-6)
    T_left_cell = invert(arm.fk(np.asarray(stop.q), "tcp") @ invert(head_frame(stereo)))
    center = T_left_cell[:3, :3] @ hole.position_m + T_left_cell[:3, 3] + [offset_m, 0.0, 0.0]
    t = np.linspace(0.0, 2 * np.pi, 100, endpoint=False)[:, None]
    rim = center + 0.5 * hole.diameter_m * (np.cos(t) * [1.0, 0, 0] + np.sin(t) * [0, 1.0, 0])
    meas = SimpleNamespace(status=status, center_m=center, normal=np.array([0.0, 0.0, -1.0]),
                           diameter_m=hole.diameter_m, cov_center_radius=np.eye(4) * 1e-12,
                           rms_m=1e-6, n_points=100, points_m=rim,
                           inliers=np.ones(100, bool))  # fmt: skip
    monkeypatch.setattr(ih, "measure_hole", lambda *a, **k: meas)
    img = np.zeros((4, 4), np.uint8)
    result, _ = ih.inspect_hole(cell, arm, None, stereo, hole, 0, img, img,
                                np.asarray(stop.q), np.zeros(6), 0.0)  # fmt: skip
    return result


CASES = [("suspect", 1e-3, False), ("suspect", 0.0, True), ("ok", 1e-3, False)]


@pytest.mark.parametrize(("status", "offset_m", "passed"), CASES)
def test_verdict_comes_from_deviations(small_cell, monkeypatch, status, offset_m, passed) -> None:
    r = _inspect(small_cell, monkeypatch, status, offset_m)
    assert r.passed is passed
    assert r.status == (status if status == "suspect" else ("ok" if passed else "fail"))


def test_suspect_out_of_tolerance_fails_in_report(small_cell, monkeypatch, tmp_path: Path) -> None:
    r = _inspect(small_cell, monkeypatch, "suspect", 1e-3)
    files = start_run(tmp_path, small_cell.cell, small_cell.tour, "tour.json", "/dev/null")
    files.store.record_hole(r)
    assert files.store.results()[0].passed is False
    summ = summary(files.store)
    files.store.close()
    assert summ["holes_failed"] == 1 and summ["holes_suspect"] == 1
    assert write_report(tmp_path)["holes_failed"] == 1
    rows = csv.DictReader((tmp_path / "report.csv").open())
    row = next(x for x in rows if x["characteristic"] == f"{r.hole_id}.position")
    assert row["pass"] == "False" and row["decision"] == "nonconformance proven"
