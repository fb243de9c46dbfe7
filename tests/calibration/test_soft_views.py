"""A view whose image fails only a quality check (too blurred) is dropped with a warning when
the rest still determines the calibration; ``--strict`` refuses the set as before; a rest that
cannot be calibrated is refused naming the dropped views (issue 26, finding 5). The same rule
for ``calibrate cell``'s tour (its observations)."""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import pytest

from cell.calibration.capture.capture import CapturedView, TourCaptures
from cell.calibration.capture.tour import observations_of
from cell.calibration.errors import CalibrationDataError
from cell.calibration.estimate import Cameras
from cell.cli import main
from measure.synth.heads import toed_in_stereo
from measure.target import TargetSpec


@pytest.fixture(scope="module")
def soft_set(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The example set (8 views) with view 4's left image blurred past the sharpness limit."""
    folder = tmp_path_factory.mktemp("soft") / "set"
    assert main(["calibrate", "example", str(folder), "--views", "8"]) == 0
    img = cv2.imread(str(folder / "L03.png"), cv2.IMREAD_GRAYSCALE)
    cv2.imwrite(str(folder / "L03.png"), cv2.GaussianBlur(img, (0, 0), 2.0))
    return folder


def _calibrate(folder: Path, out: Path, *extra: str, poses: Path | None = None) -> int:
    return main(["calibrate", "hand-eye", "--images", str(folder), "--poses",
                 str(poses or folder / "poses.csv"), "--stereo", str(folder / "stereo.json"),
                 "--cell", "motorcycle_frame", "--cols", "8", "--rows", "6", "--pitch", "0.012",
                 "-o", str(out), *extra])  # fmt: skip


def test_a_soft_view_is_dropped_with_one_warning(soft_set: Path, tmp_path: Path, capsys) -> None:
    out = tmp_path / "cellcal.json"
    assert _calibrate(soft_set, out) == 0
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("warning: ") and "row 4: image L03.png: " in err[0]
    assert "too blurred (edge width" in err[0] and "view dropped, 7 views left" in err[0]
    assert out.is_file()


def test_strict_refuses_the_set(soft_set: Path, tmp_path: Path, capsys) -> None:
    out = tmp_path / "cellcal.json"
    assert _calibrate(soft_set, out, "--strict") == 2
    (line,) = capsys.readouterr().err.strip().splitlines()
    assert "row 4: image L03.png: too blurred" in line and not out.exists()


def test_a_rest_too_small_is_refused_naming_the_dropped_view(
    soft_set: Path, tmp_path: Path, capsys
) -> None:
    lines = (soft_set / "poses.csv").read_text().splitlines()
    poses = tmp_path / "poses.csv"
    poses.write_text("\n".join([*lines[:3], lines[4]]) + "\n")  # 3 views, one soft: 2 left
    out = tmp_path / "cellcal.json"
    assert _calibrate(soft_set, out, poses=poses) == 2
    last = capsys.readouterr().err.strip().splitlines()[-1]
    assert "without the views dropped for their quality (row 3: image L03.png: too blurred" in last
    assert "the rest cannot be calibrated: " in last and not out.exists()


def _captures(reason_left: str) -> TourCaptures:
    pts = np.zeros((48, 2))
    views = [CapturedView(f"CAL{k:02d}", np.zeros(6), float(k), pts, pts) for k in range(5)]
    views[2] = CapturedView("CAL02", np.zeros(6), 2.0, None, pts, reason_left, "")
    return TourCaptures(tuple(views), 0.0, 5.0, {})


def test_the_cell_tours_soft_view_is_dropped_unless_strict() -> None:
    spec, cams = TargetSpec("chessboard", 8, 6, 0.012), Cameras.from_stereo(toed_in_stereo())
    dropped: list = []
    obs = observations_of(_captures("too blurred (edge width 4.3 px)"), spec, cams, "tour",
                          dropped=dropped)  # fmt: skip
    assert [v.name for v in obs.views] == ["CAL00", "CAL01", "CAL03", "CAL04"]
    assert [(d.row, d.reason) for d in dropped] == [
        ("CAL02", "left image: too blurred (edge width 4.3 px)")]  # fmt: skip
    with pytest.raises(CalibrationDataError, match="row CAL02: left image: too blurred"):
        observations_of(_captures("too blurred (edge width 4.3 px)"), spec, cams, "tour", True)
    with pytest.raises(CalibrationDataError, match="row CAL02: left image: target not found"):
        observations_of(_captures("target not found"), spec, cams, "tour")
