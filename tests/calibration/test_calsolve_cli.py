"""``holecell calibrate hand-eye`` on rendered images and a poses CSV, its refusals, and the
stereo calibration's two invocations."""

from __future__ import annotations

import csv
import shutil
from pathlib import Path

import cv2
import numpy as np
import pytest
from calsolve_fixtures import SMALL_STEREO, seen_views, small_truth, write_rendered_set

from cell.calibration.estimate import pose_error, truth_in_gauge
from cell.calibration.file import load_calibration
from cell.cli import build_parser, main
from cell.config import load_cell

CELL = Path(__file__).resolve().parents[2] / "cell" / "data" / "motorcycle_frame.yaml"
BOARD = ["--cols", "8", "--rows", "6", "--pitch", "0.012"]


@pytest.fixture(scope="module")
def rendered(tmp_path_factory):
    tr = small_truth(0)
    Q = seen_views(tr, 10, seed=1)
    folder = tmp_path_factory.mktemp("views")
    write_rendered_set(tr, Q, folder / "joints", joints=True)
    write_rendered_set(tr, Q, folder / "flange", joints=False)
    SMALL_STEREO.save(folder / "stereo.json")
    return tr, folder


def _rows(path: Path) -> list[list[str]]:
    with path.open() as fh:
        return list(csv.reader(fh))


def _write(path: Path, rows: list[list[str]]) -> Path:
    with path.open("w", newline="") as fh:
        csv.writer(fh).writerows(rows)
    return path


def _run(folder: Path, poses: Path, out: Path, *extra: str) -> int:
    args = ["calibrate", "hand-eye", "--images", str(folder), "--poses", str(poses)]
    return main([*args, *extra, *BOARD, "-o", str(out)])


def test_stereo_pairs_with_joints_and_the_cell(rendered, tmp_path: Path, capsys) -> None:
    tr, folder = rendered
    out = tmp_path / "cellcal.json"
    d = folder / "joints"
    code = _run(
        d, d / "poses.csv", out, "--stereo", str(folder / "stereo.json"), "--cell", str(CELL)
    )
    text = capsys.readouterr().out
    assert code == 0, text
    assert "fixed dh.d6_m: redundant with the hand-eye" in text and "OpenCV park" in text
    cal = load_calibration(out)
    assert cal.provenance.robot_model == load_cell(CELL).robot.model
    assert cal.provenance.tool_fingerprint and cal.provenance.stereo_fingerprint
    truth = truth_in_gauge(tr)
    dp, da = pose_error(cal.T_tool0_camera.T, truth.T_tool0_camera)
    # detected corners of rendered 320x256 images: a little bias on top of the noise
    assert dp < 5 * np.linalg.norm(cal.T_tool0_camera.sigma_xyz_m) + 0.1e-3
    assert da < 5 * np.linalg.norm(cal.T_tool0_camera.sigma_rot_rad) + np.deg2rad(0.01)
    assert max(cal.residual_rms_px.values()) < 0.5


def test_mono_images_with_flange_poses_and_filestorage_intrinsics(rendered, tmp_path: Path) -> None:
    tr, folder = rendered
    src = folder / "flange"
    rows = _rows(src / "poses.csv")
    mono = [["image", *rows[0][2:]]] + [[r[0], *r[2:]] for r in rows[1:]]
    poses = _write(tmp_path / "poses.csv", mono)
    fs = cv2.FileStorage(str(tmp_path / "camera.yaml"), cv2.FILE_STORAGE_WRITE)
    fs.write("camera_matrix", SMALL_STEREO.K_left)
    fs.write("distortion_coefficients", SMALL_STEREO.dist_left.reshape(1, -1))
    fs.release()
    out = tmp_path / "cellcal.json"
    assert _run(src, poses, out, "--intrinsics", str(tmp_path / "camera.yaml")) == 0
    cal = load_calibration(out)
    assert cal.T_left_right is None and cal.dh_terms == ()
    dp, _da = pose_error(cal.T_tool0_camera.T, tr.truth.T_tool0_camera)
    assert dp < 0.5e-3


def _edited(rendered, tmp_path: Path, which: str, edit) -> tuple[Path, Path]:
    _tr, folder = rendered
    d = tmp_path / "set"
    shutil.copytree(folder / which, d)
    rows = _rows(d / "poses.csv")
    edit(rows, d)
    return d, _write(d / "poses.csv", rows)


def _mm(rows, _d):
    for r in rows[1:]:
        r[2:5] = [f"{float(v) * 1000:.6f}" for v in r[2:5]]


def _deg(rows, _d):
    for r in rows[1:]:
        r[2:8] = [f"{np.rad2deg(float(v)):.6f}" for v in r[2:8]]


def _no_image(rows, _d):
    rows[3][1] = ""


def _missing_column(rows, _d):
    for r in rows:
        del r[7]


def _blank(rows, d):
    cv2.imwrite(str(d / rows[4][0]), np.full((256, 320), 128, np.uint8))


def _few(rows, _d):
    del rows[3:]


@pytest.mark.parametrize(
    ("which", "edit", "message"),
    [
        ("flange", _mm, "row 1: column x_m = .*looks like millimetres"),
        ("joints", _deg, "row 1: column q.*looks like degrees"),
        ("joints", _no_image, "row 3: no image file name in column right_image"),
        ("joints", _missing_column, "missing column.*q6_rad"),
        ("joints", _blank, "row 4: image L03.png: target not found"),
        ("joints", _few, r"2 view\(s\)"),
    ],
)
def test_bad_inputs_are_refused_in_one_line_and_nothing_is_written(
    rendered, tmp_path: Path, capsys, which, edit, message
) -> None:
    _tr, folder = rendered
    d, poses = _edited(rendered, tmp_path, which, edit)
    out = tmp_path / "cellcal.json"
    extra = ["--stereo", str(folder / "stereo.json")] + (
        ["--cell", str(CELL)] if which == "joints" else []
    )
    assert _run(d, poses, out, *extra) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "Traceback" not in err
    import re

    assert re.search(message, err), err
    assert "poses.csv" in err or "view" in err
    assert not out.exists()


def test_joints_without_a_cell_say_so(rendered, tmp_path: Path, capsys) -> None:
    _tr, folder = rendered
    d = folder / "joints"
    assert (
        _run(d, d / "poses.csv", tmp_path / "c.json", "--stereo", str(folder / "stereo.json")) == 2
    )
    assert "give the cell file with --cell" in capsys.readouterr().err


def test_calibrate_stereo_and_the_older_form_reach_the_stereo_calibration(capsys) -> None:
    stereo_args = ["--left", "l*.png", "--right", "r*.png", *BOARD]
    new = build_parser(["calibrate"]).parse_args(["calibrate", "stereo", *stereo_args])
    old = build_parser(["calibrate"]).parse_args(["calibrate", *stereo_args])
    from cell.commands import calibrate_stereo_cmd

    assert new.handler is calibrate_stereo_cmd.run
    assert old.left == new.left == ["l*.png"] and old.pitch == 0.012
    assert main(["calibrate"]) == 2
    assert "give a subcommand (stereo, hand-eye, cell, example)" in capsys.readouterr().err


def test_a_blurred_image_is_refused_with_strict_unless_a_wider_edge_is_allowed(
    rendered, tmp_path: Path, capsys
) -> None:
    def blur(rows, d):
        img = cv2.imread(str(d / rows[2][0]), cv2.IMREAD_GRAYSCALE)
        cv2.imwrite(str(d / rows[2][0]), cv2.GaussianBlur(img, (0, 0), 2.0))

    _tr, folder = rendered
    d, poses = _edited(rendered, tmp_path, "flange", blur)
    out = tmp_path / "cellcal.json"
    stereo = ["--stereo", str(folder / "stereo.json")]
    assert _run(d, poses, out, *stereo, "--strict") == 2
    assert "row 2: image L01.png: too blurred (edge width" in capsys.readouterr().err
    assert not out.exists()
    assert _run(d, poses, out, *stereo) == 0  # by default: dropped with a warning
    assert "row 2: image L01.png: too blurred" in capsys.readouterr().err
    assert load_calibration(out).counts["views"] == 9
    assert _run(d, poses, out, *stereo, "--max-edge-width", "8") == 0
    assert load_calibration(out).counts["views"] == 10
