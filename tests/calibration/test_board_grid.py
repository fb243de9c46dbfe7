"""A board size given wrong is not "found" (issue 26, finding 3): OpenCV's SB detector takes the
plate's outer edge for one more column of corners on the 8 x 6 example board given as 9 x 6;
the corners must form the board's grid (homography residual, spacing, the plate's border)
before a detection counts, and the refusal then gives the board-size hint."""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import pytest

from cell.cli import main
from measure.target import _SB, TargetSpec, find_target
from measure.target_grid import grid_problem


@pytest.fixture(scope="module")
def example(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("ex") / "set"
    assert main(["calibrate", "example", str(folder)]) == 0
    return folder


def test_the_plate_edge_is_not_a_ninth_column(example: Path) -> None:
    spec = TargetSpec("chessboard", 9, 6, 0.012)
    grid = spec.object_points()[:, :2] / spec.pitch_m
    fooled = 0
    for path in sorted(example.glob("L*.png"), reverse=True):  # the last views fool it
        img = cv2.imread(str(path), cv2.IMREAD_GRAYSCALE)
        right = find_target(img, TargetSpec("chessboard", 8, 6, 0.012))
        assert right.points is not None, (path.name, right.reason)
        # what OpenCV alone returns on some views: 54 "corners", a column on the plate's edge
        found, pts = cv2.findChessboardCornersSB(img, (9, 6), flags=_SB)
        if not found:
            continue
        fooled += 1
        problem = grid_problem(img, pts.reshape(-1, 2), grid, 9, 6, True)
        assert "no board square beyond" in problem, (path.name, problem)
        wrong = find_target(img, spec)
        assert wrong.points is None and wrong.reason.startswith("not a 9 x 6 board: ")
        break
    assert fooled == 1


def test_uneven_or_bent_grids_are_refused() -> None:
    spec = TargetSpec("chessboard", 8, 6, 0.012)
    grid = spec.object_points()[:, :2] / spec.pitch_m
    pts = 100 + 30.0 * grid  # a fronto-parallel board, 30 px per square
    img = np.full((400, 500), 128, np.uint8)  # no board: the border test cannot judge
    assert grid_problem(img, pts, grid, 8, 6, True) == ""
    uneven = pts.copy()
    uneven[grid[:, 0] == 7, 0] += 20.0  # the last column 1.67 pitches out
    assert "uneven corner spacing" in grid_problem(img, uneven, grid, 8, 6, True)
    bent = pts.copy()
    bent[:, 1] += 3.0 * (grid[:, 0] - 3.5) ** 2  # a 37 px sag over 7 squares: no plane
    assert "homography residual" in grid_problem(img, bent, grid, 8, 6, False)


def test_calibrate_with_a_wrong_board_size_gets_the_hint(
    example: Path, tmp_path: Path, capsys
) -> None:
    out = tmp_path / "cellcal.json"
    lines = (example / "poses.csv").read_text().splitlines()
    poses = tmp_path / "poses.csv"  # the first view, then the two the SB detector is fooled by
    poses.write_text("\n".join([lines[0], lines[1], lines[11], lines[12]]) + "\n")
    code = main(["calibrate", "hand-eye", "--images", str(example), "--poses", str(poses),
                 "--stereo", str(example / "stereo.json"),
                 "--cell", "motorcycle_frame", "--cols", "9", "--rows", "6", "--pitch", "0.012",
                 "-o", str(out)])  # fmt: skip
    assert code == 2
    (line,) = capsys.readouterr().err.strip().splitlines()
    assert "row 1: image L00.png: " in line
    assert "is the board size right? --cols 9 --rows 6" in line
    assert not out.exists()
