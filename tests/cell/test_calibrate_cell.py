"""``holecell calibrate cell`` end to end against the simulated cell (SimCell, its controller on a
pty and its camera server), and the chessboard corner order.

The default tests use a quarter-resolution copy of the standard head (the same optics, 612 x 512
px) so that rendering and detection take a fraction of a second per view, and small tours
planned once per module; the slow test runs the full head on a 30-view tour.
"""

from __future__ import annotations

import gc
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
import yaml

from cell.calibration.capture import orient_chessboard, refine_corners
from cell.calibration.estimate import pose_error
from cell.calibration.file import cell_provenance, check_belongs, load_calibration
from cell.calibration.plan import (
    CALIBRATE_MARGIN_FRAC,
    CALIBRATE_OFFSETS,
    CalibrationPlanOptions,
    cell_target,
    plan_calibration,
)
from cell.camera import cell_stereo
from cell.cli import main
from cell.config import builtin_cell_path, load_cell
from cell.config.tours import hole_stops
from cell.demo.calibration_truth import calibration_tcp_errors_m, true_state
from cell.sim.camserver import CameraServer
from cell.sim.session import SimCell
from cell.sim.truth import CellTruth
from cell.sim.world import WorldOptions
from measure.synth.heads import STANDARD_PIXEL_M, toed_in_stereo
from measure.synth.targets import render_target_pair
from measure.target import find_target
from planner import Options
from planner.calibration import CalibrationTour, CandidateOptions
from robots.transforms import invert

SMALL_SIZE = (612, 512)
#: warm-up time of the simulated arm: thermally steady, so the truth is the same all tour long
STEADY_S = 1.0e6


def _small_cell(folder: Path) -> Path:
    """The built-in cell with a quarter-resolution head (same field of view)."""
    st = toed_in_stereo(image_size=SMALL_SIZE, pixel_m=4 * STANDARD_PIXEL_M)
    st.save(folder / "stereo_small.json")
    data = yaml.safe_load(builtin_cell_path().read_text())
    data["tool"]["calibration"] = "stereo_small.json"
    path = folder / "cell.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def _plan(cell, views: int) -> CalibrationTour:
    """A quick plan: fewer candidates, the geometric design, no prediction."""
    cand = CandidateOptions(
        tilts_deg=(0.0, 20.0, 35.0),
        azimuths=4,
        roll_step_deg=90.0,
        offsets=CALIBRATE_OFFSETS,
        margin_frac=CALIBRATE_MARGIN_FRAC,
    )
    o = CalibrationPlanOptions(
        views=views, criterion="geometric", predict=False, candidates=cand, tour=Options(seed=0)
    )
    tour = plan_calibration(cell, cell_target(cell), cell_stereo(cell), hole_stops(cell)[1], o)
    gc.collect()
    return tour


@pytest.fixture(scope="module")
def small(tmp_path_factory: pytest.TempPathFactory) -> dict:
    folder = tmp_path_factory.mktemp("calcell")
    path = _small_cell(folder)
    cell = load_cell(path)
    tours = {}
    for n in (2, 12):
        tours[n] = folder / f"caltour{n}.json"
        _plan(cell, n).save(tours[n])
    return {"folder": folder, "cell": path, "tours": tours}


def _calibrate(cell_path: Path, tour: Path, out: Path, truth: CellTruth, capsys):
    cell = load_cell(cell_path)
    with SimCell.start(cell, WorldOptions(speed=20.0, drift_offset_s=STEADY_S, truth=truth)) as sim:
        cam = CameraServer(sim.camera).start()
        try:
            args = ["calibrate", "cell", str(cell_path), "--port", sim.url, "--camera", cam.url,
                    "--tour", str(tour), "-o", str(out), "--settle-s", "0", "--quiet"]  # fmt: skip
            code = main(args)
        finally:
            cam.close()
        captured = capsys.readouterr()
        return code, captured, sim, cell


def test_calibrate_cell_end_to_end_finds_the_true_head(small: dict, tmp_path: Path, capsys) -> None:
    out = tmp_path / "cellcal.json"
    truth = CellTruth.drawn(0)
    code, cap, sim, cell = _calibrate(small["cell"], small["tours"][12], out, truth, capsys)
    assert code == 0, cap.err
    for figure in ("T_tool0_camera", "reprojection RMS", "D-H errors", "robot time", "solve"):
        assert figure in cap.out
    cal = load_calibration(out)
    stereo = cell_stereo(cell)
    check_belongs(cal, cell_provenance(cell, cell.build_robot().dh, None, stereo.to_dict()))
    ts = sim.camera.true_stereo
    T_rl = np.eye(4)
    T_rl[:3, :3], T_rl[:3, 3] = ts.R, ts.T
    tr = true_state(cell.build_robot().dh, sim.camera.geometry, invert(T_rl), 0.0)
    dp, da = pose_error(cal.T_tool0_camera.T, tr.T_tool0_camera)
    nominal = np.asarray(cell.T_tool0_tcp()) @ sim.camera.geometry.T_tcp_left
    dp0, da0 = pose_error(nominal, tr.T_tool0_camera)
    # 12 views of a quarter-resolution head: the head's 1 mm, 0.3 deg error falls well below
    assert dp < 0.3 * dp0 and da < 0.3 * da0, (dp, da, dp0, da0)
    q = hole_stops(cell)[1][:20]
    e = calibration_tcp_errors_m(cal, tr, invert(sim.camera.geometry.T_tcp_left), q)
    assert np.sqrt(np.mean(e**2)) < 0.5e-3


def test_view_without_the_target_is_refused_and_nothing_written(
    small: dict, tmp_path: Path, capsys
) -> None:
    out = tmp_path / "cellcal.json"
    moved = np.eye(4)
    moved[:3, 3] = (0.04, 0.0, 0.0)  # the plate 40 mm off where the cell file puts it
    truth = replace(CellTruth.zero(), target_placement_error=moved)
    code, cap, _sim, _cell = _calibrate(small["cell"], small["tours"][12], out, truth, capsys)
    assert code == 2
    line = cap.err.strip()
    assert "\n" not in line and "row CAL" in line and "target not found" in line, line
    assert not out.exists() and not list(tmp_path.glob("*.tmp"))


def test_too_few_views_are_refused(small: dict, tmp_path: Path, capsys) -> None:
    out = tmp_path / "cellcal.json"
    code, cap, _sim, _cell = _calibrate(small["cell"], small["tours"][2], out, CellTruth.zero(),
                                        capsys)  # fmt: skip
    assert code == 2 and "2 view(s)" in cap.err and "at least 3" in cap.err, cap.err
    assert not out.exists()


def test_tour_of_another_cell_is_refused_before_connecting(
    small: dict, tmp_path: Path, capsys
) -> None:
    out = tmp_path / "cellcal.json"
    tour = str(small["tours"][2])
    code = main(["calibrate", "cell", "--port", "/dev/null-no-such-port", "--camera",
                 "tcp://127.0.0.1:1", "--tour", tour, "-o", str(out)])  # fmt: skip
    err = capsys.readouterr().err
    assert code == 2 and "plan the tour for this cell" in err, err
    assert not out.exists()


@pytest.mark.parametrize("roll_deg", [0.0, 180.0, 90.0])
def test_chessboard_corners_come_in_the_board_order(roll_deg: float) -> None:
    cell = load_cell(None)
    spec = cell.calibration_target.target_spec()
    st = toed_in_stereo(image_size=SMALL_SIZE, pixel_m=4 * STANDARD_PIXEL_M)
    from scipy.spatial.transform import Rotation

    P = spec.object_points()
    centre = 0.5 * (P.min(axis=0) + P.max(axis=0))
    T = np.eye(4)
    T[:3, :3] = Rotation.from_euler("zx", [roll_deg, 15.0], degrees=True).as_matrix()
    T[:3, 3] = np.array([0.0, 0.0, 0.25]) - T[:3, :3] @ centre
    r = render_target_pair(st, spec, T, supersample=1, seed=1)
    import cv2

    rv, _ = cv2.Rodrigues(T[:3, :3])
    uv = cv2.projectPoints(P, rv, T[:3, 3], st.K_left, st.dist_left)[0].reshape(-1, 2)
    det = find_target(r.left, spec)
    assert det.points is not None
    pts = refine_corners(r.left, orient_chessboard(r.left, det.points, spec), spec)
    assert np.sqrt(np.mean(np.sum((pts - uv) ** 2, axis=1))) < 0.5
    flipped = det.points[::-1]  # the detector's other order: turned by 180 deg
    np.testing.assert_allclose(orient_chessboard(r.left, flipped, spec), orient_chessboard(
        r.left, det.points, spec))  # fmt: skip


@pytest.mark.slow
def test_calibrate_cell_full_head_30_views(tmp_path: Path, capsys) -> None:
    """The built-in cell's head, 30 views planned as calibrate cell plans them, seed 1."""
    from cell.calibration.plan import calibrate_plan_options, plan_cell_calibration

    cell = load_cell(None)
    tour = tmp_path / "caltour.json"
    plan_cell_calibration(cell, cell_stereo(cell), calibrate_plan_options(30)).save(tour)
    out = tmp_path / "cellcal.json"
    code, cap, sim, cell = _calibrate(builtin_cell_path(), tour, out, CellTruth.drawn(1), capsys)
    assert code == 0, cap.err
    cal = load_calibration(out)
    ts = sim.camera.true_stereo
    T_rl = np.eye(4)
    T_rl[:3, :3], T_rl[:3, 3] = ts.R, ts.T
    tr = true_state(cell.build_robot().dh, sim.camera.geometry, invert(T_rl), 0.0)
    dp, da = pose_error(cal.T_tool0_camera.T, tr.T_tool0_camera)
    assert dp < 0.15e-3 and np.degrees(da) < 0.02, (dp, np.degrees(da))


def test_a_corner_off_the_plate_plane_is_refined_again() -> None:
    from cell.calibration.capture import plane_outliers, repair_outliers

    spec = load_cell(None).calibration_target.target_spec()
    st = toed_in_stereo(image_size=SMALL_SIZE, pixel_m=4 * STANDARD_PIXEL_M)
    P = spec.object_points()
    T = np.eye(4)
    T[:3, 3] = np.array([0.0, 0.0, 0.25]) - 0.5 * (P.min(axis=0) + P.max(axis=0))
    r = render_target_pair(st, spec, T, supersample=1, seed=2)
    det = find_target(r.left, spec)
    good = refine_corners(r.left, orient_chessboard(r.left, det.points, spec), spec)
    assert plane_outliers(good, spec, st.K_left, st.dist_left)[0].max() < 1.0
    bad = good.copy()
    bad[0] += (6.0, -5.0)  # a corner the detector put on the wrong spot
    off, _ = plane_outliers(bad, spec, st.K_left, st.dist_left)
    assert off[0] > 5.0 and np.delete(off, 0).max() < 1.0
    fixed, why = repair_outliers(r.left, bad, spec, st.K_left, st.dist_left)
    assert why == "" and np.linalg.norm(fixed[0] - good[0]) < 0.5


def test_views_detected_in_workers_equal_views_detected_in_this_process(small: dict) -> None:
    """The simulated head's snapshots rendered and detected in 2 worker processes give the
    features one process gives, view by view, in the tour's order."""
    from cell.calibration.capture import CaptureSettings, TourCapture, check_calibration_tour
    from cell.link.client import ControllerClient
    from planner.calibration import load_caltour

    cell = load_cell(small["cell"])
    tour = load_caltour(small["tours"][12])
    spec = check_calibration_tour(cell, tour, "test tour")
    views = {}
    for workers in (0, 2):
        opts = WorldOptions(speed=20.0, drift_offset_s=STEADY_S, truth=CellTruth.drawn(0))
        with SimCell.start(cell, opts) as sim:
            client = ControllerClient(sim.url)
            client.connect()
            try:
                settings = CaptureSettings(settle_s=0.0, workers=workers)
                cap = TourCapture(tour.tour, client, sim.camera, spec, settings).run()
            finally:
                client.close()
        views[workers] = cap.views
        assert cap.wall_s["cpu_s"] > 0.0 and cap.wall_s["render_s"] > 0.0  # snapshots
    assert (
        [v.id for v in views[0]] == [v.id for v in views[2]] == [s.hole_id for s in tour.tour.stops]
    )
    for a, b in zip(views[0], views[2], strict=True):
        np.testing.assert_array_equal(a.q_rad, b.q_rad)
        for pa, pb in ((a.corners_left_px, b.corners_left_px),
                       (a.corners_right_px, b.corners_right_px)):  # fmt: skip
            assert pa is not None and pb is not None
            np.testing.assert_array_equal(pa, pb)
