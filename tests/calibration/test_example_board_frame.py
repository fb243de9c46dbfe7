"""``holecell calibrate example``'s truth and the calibration it leads to share one board frame
(issue 26, finding 2; docs/conventions.md: x along a row, y down the rows, z into the plate, the
camera looking at the printed face along +z): their ``T_base_target`` agree, not only the
hand-eye (they differed by 180 deg about x and 5 pitches in y)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from cell.calibration.file import load_calibration
from cell.cli import main


def _angle_deg(R: np.ndarray) -> float:
    return float(np.degrees(np.linalg.norm(Rotation.from_matrix(R).as_rotvec())))


def test_the_example_truth_and_its_calibration_share_the_board_frame(
    tmp_path: Path, capsys
) -> None:
    folder = tmp_path / "set"
    assert main(["calibrate", "example", str(folder), "--views", "8"]) == 0
    out = folder / "cellcal.json"
    assert main(["calibrate", "hand-eye", "--images", str(folder), "--poses",
                 str(folder / "poses.csv"), "--stereo", str(folder / "stereo.json"), "--cell",
                 "motorcycle_frame", "--cols", "8", "--rows", "6", "--pitch", "0.012", "-o",
                 str(out)]) == 0  # fmt: skip
    capsys.readouterr()
    truth = json.loads((folder / "truth.json").read_text())
    cal = load_calibration(out)
    for key, est in (("T_base_target", cal.T_base_target.T),
                     ("T_tool0_camera", cal.T_tool0_camera.T)):  # fmt: skip
        d = np.linalg.inv(np.asarray(truth[key])) @ est
        assert np.linalg.norm(d[:3, 3]) < 0.3e-3, (key, d)
        assert _angle_deg(d[:3, :3]) < 0.05, (key, d)
    # the convention itself: the plate lies face up, so its z (into the plate) points down
    z_base = np.asarray(truth["T_base_target"])[:3, 2]
    assert z_base[2] < -0.99, z_base
