"""``holecell run --calibration``: the file is checked against the run's cell, the run's
kinematics are the calibrated ones, each stop is corrected for them and the budget gains the
calibration's covariance."""

from __future__ import annotations

import json
from dataclasses import replace
from datetime import UTC, datetime, timedelta
from pathlib import Path

import numpy as np
import pytest
import yaml
from cell_fixtures import SmallCell

from cell.calibration.errors import CalibrationFileError
from cell.calibration.file import save_calibration
from cell.calibration.use import (
    MAX_AGE_DAYS,
    RunGeometry,
    StopCorrectionError,
    correct_tour,
    load_run_calibration,
    store_calibration,
)
from cell.camera import cell_stereo
from cell.cli import main
from cell.config import load_cell
from cell.config.tours import stop_rows
from cell.demo.sim_calibration import design_views, simulated_calibration
from cell.sim.truth import CellTruth
from cell.sim.world import SimWorld, WorldOptions
from measure import head_frame
from robots.transforms import invert


@pytest.fixture(scope="module")
def calibrated(small_cell: SmallCell, tmp_path_factory: pytest.TempPathFactory):
    """A calibration of the small cell with the realistic truth of seed 3, as a file."""
    cell = small_cell.cell
    truth = CellTruth.drawn(3, cell)
    world = SimWorld(cell, WorldOptions(truth=truth, drift_offset_s=0.0))  # a cold arm
    st = cell_stereo(cell)
    q_views = design_views(cell, st, np.array([s.q for s in small_cell.tour.stops]), 30)
    res = simulated_calibration(cell, world.true_geometry(), st, truth.repeatability_rp_m,
                                q_views, seed=3)  # fmt: skip
    path = tmp_path_factory.mktemp("cal") / "cellcal.json"
    save_calibration(res.calibration, path)
    return path, world, res.calibration


def _other_cell(small_cell: SmallCell, tmp_path: Path, edit) -> object:
    data = yaml.safe_load(small_cell.path.read_text())
    edit(data)
    p = tmp_path / "other.yaml"
    p.write_text(yaml.safe_dump(data, sort_keys=False))
    return load_cell(p)


def _load(path, cell, **kw):
    return load_run_calibration(path, cell, cell.build_robot(), cell_stereo(cell), **kw)


def test_a_calibration_of_this_cell_is_accepted(small_cell: SmallCell, calibrated) -> None:
    path, _, cal = calibrated
    rc = _load(path, small_cell.cell)
    assert rc.calibration.created_utc == cal.created_utc
    assert rc.info()["file"] == str(path) and rc.info()["age_days"] < 1.0


@pytest.mark.parametrize(
    ("edit", "field"),
    [
        (lambda d: d["tool"].update(standoff_m=d["tool"]["standoff_m"] + 0.01), "tool.fingerprint"),
        (lambda d: d.update(name="another_cell"), "cell.fingerprint"),
        (lambda d: d["robot"].update(model="abb_irb4600_60_205"), "robot.fingerprint"),
    ],
)
def test_a_calibration_of_another_cell_is_refused(
    small_cell: SmallCell, calibrated, tmp_path: Path, edit, field: str
) -> None:
    path, _, _ = calibrated
    cell = _other_cell(small_cell, tmp_path, edit)
    with pytest.raises(CalibrationFileError) as exc:
        _load(path, cell)
    msg = str(exc.value)
    assert msg.startswith(f"{path}: {field}: belongs to another") and "\n" not in msg


def test_an_old_calibration_is_refused_unless_the_limit_is_raised(
    small_cell: SmallCell, calibrated
) -> None:
    path, _, cal = calibrated
    made = datetime.strptime(cal.created_utc, "%Y-%m-%dT%H:%M:%SZ").replace(tzinfo=UTC)
    later = made + timedelta(days=MAX_AGE_DAYS + 1)
    with pytest.raises(CalibrationFileError, match=r"created_utc: made 8\.0 days ago, older than"):
        _load(path, small_cell.cell, now=later)
    assert _load(path, small_cell.cell, now=later, max_age_days=30.0).source == str(path)


def _kabsch_rms(a: np.ndarray, b: np.ndarray) -> float:
    """RMS (m) of ``a`` best-fitted rigidly onto ``b`` (both (N, 3))."""
    ca, cb = a.mean(0), b.mean(0)
    U, _, Vt = np.linalg.svd((a - ca).T @ (b - cb))
    d = np.sign(np.linalg.det(Vt.T @ U.T))
    R = Vt.T @ np.diag([1.0, 1.0, d]) @ U.T
    return float(np.sqrt(np.mean(np.sum(((a - ca) @ R.T + cb - b) ** 2, axis=1))))


def test_the_calibrated_geometry_follows_the_true_cell(small_cell: SmallCell, calibrated) -> None:
    """A point 0.25 m in front of the left camera at poses around the tour's stops: the
    calibrated chain agrees with the true one up to a rigid motion (the base, which the plate
    alone cannot tie to the cell) to tens of um; the nominal chain is off by hundreds."""
    path, world, _ = calibrated
    cell = small_cell.cell
    arm = cell.build_arm()
    st = cell_stereo(cell)
    geo = RunGeometry(arm, st, _load(path, cell))
    nominal = RunGeometry(arm, st, None)
    truth = world.true_geometry()
    T_tcp_left = invert(head_frame(st))
    rng = np.random.default_rng(0)
    p = np.array([0.0, 0.0, 0.25, 1.0])
    stops = np.array([s.q for s in small_cell.tour.stops])
    Q = stops[rng.integers(len(stops), size=100)] + rng.normal(0.0, 0.1, (100, 6))
    true = np.array([(truth.T_cell_left(q, 0.0) @ p)[:3] for q in Q])
    cal = np.array([(geo.fk(q) @ T_tcp_left @ p)[:3] for q in Q])
    nom = np.array([(nominal.fk(q) @ T_tcp_left @ p)[:3] for q in Q])
    assert _kabsch_rms(cal, true) < 30e-6
    assert _kabsch_rms(nom, true) > 100e-6
    np.testing.assert_allclose(nominal.fk(Q[0]), arm.fk(Q[0]), atol=1e-9)


def test_each_stop_is_corrected_so_the_calibrated_head_reaches_the_plan(
    small_cell: SmallCell, calibrated
) -> None:
    path, _, _ = calibrated
    cell = small_cell.cell
    arm = cell.build_arm()
    geo = RunGeometry(arm, cell_stereo(cell), _load(path, cell))
    tour, corrections = correct_tour(small_cell.tour, arm, geo)
    stop_rows(tour)  # every corrected stop is on the corrected trajectory
    for s, s0, c in zip(tour.stops, small_cell.tour.stops, corrections, strict=True):
        np.testing.assert_allclose(geo.fk(s.q), arm.fk(s0.q), atol=1e-8)
        assert 1e-5 < np.abs(c.dq_rad).max() < 0.02  # mrad: a mm-sized correction
        assert 1e-4 < np.linalg.norm(c.offset_m) < 1e-2
    traj0, traj = np.asarray(small_cell.tour.trajectory), np.asarray(tour.trajectory)
    np.testing.assert_array_equal(traj[[0, -1]], traj0[[0, -1]])  # home is not moved
    # the correction is smooth: the step between two rows changes by micro-radians only
    assert np.abs(np.diff(traj - traj0, axis=0)).max() < 1e-4


def test_a_stop_the_correction_takes_out_of_limits_is_refused(
    small_cell: SmallCell, calibrated
) -> None:
    path, _, _ = calibrated
    cell = small_cell.cell
    arm = cell.build_arm()
    geo = RunGeometry(arm, cell_stereo(cell), _load(path, cell))
    q0 = np.asarray(small_cell.tour.stops[1].q)
    arm.lower, arm.upper = np.minimum(arm.lower, q0), np.maximum(arm.upper, q0)
    arm.lower[3] = arm.upper[3] = q0[3]  # joint 4 pinned at the planned value
    with pytest.raises(StopCorrectionError, match=r"tour: stop 0 \(.*\): the corrected joint"):
        correct_tour(replace(small_cell.tour), arm, geo)


def test_run_refuses_a_calibration_of_another_cell_before_connecting(
    small_cell: SmallCell, calibrated, tmp_path: Path, capsys
) -> None:
    path, _, _ = calibrated
    data = json.loads(Path(path).read_text())
    data["cell"]["fingerprint"] = "0" * 16
    bad = tmp_path / "other_cal.json"
    bad.write_text(json.dumps(data))
    out = tmp_path / "run"
    code = main(["run", str(small_cell.tour_path), "--cell", str(small_cell.path), "--port",
                 "socket://127.0.0.1:9", "--camera", "tcp://127.0.0.1:9", "--out", str(out),
                 "--calibration", str(bad), "--quiet", "--yes"])  # fmt: skip
    err = capsys.readouterr().err.strip()
    assert code == 2 and not out.exists()
    assert err.count("\n") == 0 and "cell.fingerprint: belongs to another cell" in err


def test_the_calibration_is_stored_with_the_run(calibrated, tmp_path: Path) -> None:
    path, _, _ = calibrated
    from cell.calibration.file import load_calibration
    from cell.calibration.use import CalibratedKinematics, RunCalibration, calibration_summary

    cal = load_calibration(path)
    dest = store_calibration(RunCalibration(cal, CalibratedKinematics(cal), str(path)), tmp_path)
    assert dest.read_bytes() == Path(path).read_bytes()
    info = calibration_summary(tmp_path)
    assert info["file"] == str(dest) and info["created_utc"] == cal.created_utc
    assert len(info["sigma_hand_eye_xyz_m"]) == 3
    assert calibration_summary(tmp_path / "nothing") is None


def test_the_run_triangulates_with_the_calibrated_stereo_extrinsics(
    small_cell: SmallCell, calibrated
) -> None:
    """The calibration's ``T_left_right`` replaces the file's; the intrinsics stay the file's,
    and the calibrated TCP still carries the left camera to the calibrated hand-eye."""
    from cell.calibration.use import calibrated_stereo

    path, _, cal = calibrated
    cell = small_cell.cell
    st = cell_stereo(cell)
    rc = _load(path, cell)
    st2 = calibrated_stereo(st, rc)
    T_rl = invert(cal.T_left_right.T)
    np.testing.assert_allclose(st2.R, T_rl[:3, :3], atol=1e-12)
    np.testing.assert_allclose(st2.T, T_rl[:3, 3], atol=1e-12)
    np.testing.assert_array_equal(st2.K_left, st.K_left)
    assert calibrated_stereo(st, None) is st
    geo = RunGeometry(cell.build_arm(), st2, rc)
    X = geo.T_tool0_tcp @ invert(head_frame(st2))
    np.testing.assert_allclose(X, cal.T_tool0_camera.T, atol=1e-12)


def test_a_resumed_run_uses_the_copy_it_stored(small_cell: SmallCell, calibrated, tmp_path):
    """``--resume`` reads RUN_DIR/cellcal.json (its age is not checked again) and refuses a
    new ``--calibration``; a run that stored none resumes without."""
    import argparse

    from cell.calibration.file import load_calibration
    from cell.calibration.use import CalibratedKinematics, RunCalibration
    from cell.commands.run_cmd import _calibration
    from cell.errors import CellError

    path, _, _ = calibrated
    cal = load_calibration(path)
    store_calibration(RunCalibration(cal, CalibratedKinematics(cal), str(path)), tmp_path)
    args = argparse.Namespace(calibration=None, calibration_max_age=0.0)  # any age would fail
    rc = _calibration(args, small_cell.cell, tmp_path)
    assert rc is not None and rc.source == str(tmp_path / "cellcal.json")
    assert _calibration(args, small_cell.cell, tmp_path / "none") is None
    with pytest.raises(CellError, match="--resume uses the calibration stored with the run"):
        _calibration(argparse.Namespace(calibration=str(path)), small_cell.cell, tmp_path)
