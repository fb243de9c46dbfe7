"""A new user's mistakes with ``holecell calibrate hand-eye``: one line each, with the hint
that leads to the fix (units of the CSV's columns, the board size); the D-H errors printed
with the unit each value is in."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from calsolve_fixtures import SMALL_STEREO, seen_views, small_truth, write_rendered_set

from cell.calibration.errors import CalibrationDataError
from cell.calibration.inputs import read_pose_csv
from cell.cli import main
from cell.commands.calibrate_report import dh_term_text

CELL = Path(__file__).resolve().parents[2] / "cell" / "data" / "motorcycle_frame.yaml"


@pytest.fixture(scope="module")
def rendered(tmp_path_factory) -> Path:
    tr = small_truth(0)
    folder = tmp_path_factory.mktemp("views")
    write_rendered_set(tr, seen_views(tr, 8, seed=1), folder, joints=True)
    SMALL_STEREO.save(folder / "stereo.json")
    return folder


def _run(folder: Path, out: Path, board: tuple[str, str], *extra: str) -> int:
    return main([
        "calibrate", "hand-eye", "--images", str(folder), "--poses", str(folder / "poses.csv"),
        "--stereo", str(folder / "stereo.json"), "--cols", board[0], "--rows", board[1],
        "--pitch", "0.012", "--cell", str(CELL), "-o", str(out), *extra,
    ])  # fmt: skip


@pytest.mark.parametrize(
    ("header", "use_joints", "found"),
    [
        ("image,q1_deg,q2_deg,q3_deg,q4_deg,q5_deg,q6_deg", True, "q1_deg..q6_deg"),
        ("image,x_mm,y_mm,z_mm,qx,qy,qz,qw", False, "x_mm, y_mm, z_mm"),
    ],
)
def test_columns_in_other_units_get_the_unit_hint(
    tmp_path: Path, header: str, use_joints: bool, found: str
) -> None:
    p = tmp_path / "poses.csv"
    p.write_text(header + "\na.png," + ",".join(["0.5"] * (header.count(",") - 1)) + ",0.5\n")
    with pytest.raises(CalibrationDataError) as exc:
        read_pose_csv(p, use_joints)
    msg = str(exc.value)
    assert msg.startswith(f"{p}: missing column(s) ") and "\n" not in msg
    assert f"found {found}, the file is in radians and metres (q1_rad, x_m)" in msg


def _copy(rendered: Path, folder: Path, rows: int | None = None) -> Path:
    folder.mkdir()
    for f in rendered.iterdir():
        (folder / f.name).write_bytes(f.read_bytes())
    if rows is not None:
        lines = (rendered / "poses.csv").read_text().splitlines()
        (folder / "poses.csv").write_text("\n".join(lines[: rows + 1]) + "\n")
    return folder


def test_a_wrong_board_size_is_hinted_when_no_image_shows_the_target(
    rendered: Path, tmp_path: Path, capsys
) -> None:
    d = _copy(rendered, tmp_path / "views", rows=3)
    out = tmp_path / "cellcal.json"
    assert _run(d, out, ("9", "6")) == 2
    (line,) = capsys.readouterr().err.strip().splitlines()
    assert "row 1: image L00.png: " in line and "nor in any other row's image" in line
    assert "is the board size right? --cols 9 --rows 6" in line and "poses.csv" in line
    assert not out.exists()


def test_the_board_size_search_is_bounded_and_says_so(
    rendered: Path, tmp_path: Path, capsys, monkeypatch
) -> None:
    from cell.calibration.inputs import images

    d = _copy(rendered, tmp_path / "views")
    monkeypatch.setattr(images, "HINT_ROWS", 2)
    assert _run(d, tmp_path / "c.json", ("7", "5")) == 2
    assert "nor in the 2 other rows' images searched" in capsys.readouterr().err


def test_one_image_without_the_target_is_named_without_the_board_hint(
    rendered: Path, tmp_path: Path, capsys
) -> None:
    import cv2
    import numpy as np

    d = _copy(rendered, tmp_path / "views")
    cv2.imwrite(str(d / "L00.png"), np.full((256, 320), 128, np.uint8))
    assert _run(d, tmp_path / "c.json", ("8", "6")) == 2
    (line,) = capsys.readouterr().err.strip().splitlines()
    assert line.endswith("row 1: image L00.png: target not found")


def test_dh_errors_carry_the_unit_of_their_value() -> None:
    assert dh_term_text("a1_m", 0.00089, 1e-5) == "a1 +0.8900 ± 0.0100 mm"
    assert dh_term_text("theta2_rad", -0.001, 0.0002) == "theta2 -0.0573 ± 0.0115 deg"


def test_the_printed_dh_errors_name_no_metre_unit_on_millimetres(
    rendered: Path, tmp_path: Path, capsys
) -> None:
    out = tmp_path / "cellcal.json"
    assert _run(rendered, out, ("8", "6")) == 0
    (line,) = [s for s in capsys.readouterr().out.splitlines() if s.startswith("D-H errors")]
    terms = line.removeprefix("D-H errors: ").split(", ")
    assert terms and all(
        re.fullmatch(r"\w+\d [+-]\d+\.\d{4} ± \d+\.\d{4} (mm|deg)", t) for t in terms
    )
    assert "_m " not in line and "_rad " not in line
