"""The public hand-eye data-set converter (benchmarks/handeye_public_sets.py) on small folders
written here in each set's own format: the pose conventions, the units and the refusals."""

from __future__ import annotations

import csv
import subprocess
import sys
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

SCRIPT = Path(__file__).resolve().parents[1] / "benchmarks" / "handeye_public_sets.py"


def _run(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, str(SCRIPT), *args], capture_output=True, text=True, timeout=120
    )


def _rows(path: Path) -> list[dict]:
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


def _visp_folder(root: Path, poses: list[np.ndarray]) -> Path:
    d = root / "data-eye-in-hand"
    d.mkdir()
    (d / "chessboard-data.txt").write_text("Chessboard\n9 x 6\nsquare size: 0.0236 m\n")
    (d / "franka_camera.xml").write_text(
        "<root><camera><model><type>perspectiveProjWithDistortion</type>"
        "<px>600</px><py>601</py><u0>320</u0><v0>240</v0><kud>-0</kud><kdu>0</kdu>"
        "</model></camera></root>"
    )
    for i, vec in enumerate(poses, start=1):
        body = "".join(f"  - [{float(v)!r}]\n" for v in vec)
        (d / f"franka_pose_rPe_{i}.yaml").write_text(f"rows: 6\ncols: 1\ndata:\n{body}")
        (d / f"franka_image-{i}.png").write_bytes(b"not an image")  # no board: dropped
    return d


def test_visp_theta_u_pose_becomes_metres_and_xyzw_quaternion(tmp_path: Path) -> None:
    rotvec = np.array([0.3, -2.8, 0.2])
    vecs = [np.array([0.335, -0.032, 0.308, *rotvec]), np.array([0.4, 0.1, 0.3, 0, 0, 0.5])]
    d = _visp_folder(tmp_path, vecs)
    out = tmp_path / "out"
    res = _run("convert", "visp", str(d), "-o", str(out))
    assert res.returncode == 0, res.stderr
    rows = _rows(out / "poses.csv")
    assert [r["image"] for r in rows] == ["franka_image-1.png", "franka_image-2.png"]
    got = np.array([float(rows[0][k]) for k in ("x_m", "y_m", "z_m")])
    np.testing.assert_allclose(got, vecs[0][:3], atol=1e-9)
    q = np.array([float(rows[0][k]) for k in ("qx", "qy", "qz", "qw")])
    assert q[3] >= 0
    R_expected = Rotation.from_rotvec(rotvec).as_matrix()
    np.testing.assert_allclose(Rotation.from_quat(q).as_matrix(), R_expected, atol=1e-9)
    yaml_text = (out / "intrinsics.yaml").read_text()
    assert "camera_matrix" in yaml_text and "distortion_coefficients" in yaml_text
    assert "board found in 0" in res.stdout  # the unreadable images are named, not hidden


def _kuka_folder(root: Path, T: np.ndarray, n: int = 2) -> Path:
    d = root / "kuka_1"
    d.mkdir()
    (d / "squaresize.txt").write_text("20mm")
    (d / "RobotPosesVec.txt").write_text(
        "".join("\t".join(f"{v:.9f}" for v in T.ravel()) + "\n" for _ in range(n))
    )
    for i in range(1, n + 1):
        (d / f"{i:02d}.png").write_bytes(b"x")
    return d


def test_kuka_row_major_matrix_in_metres_is_read_and_millimetres_refused(tmp_path: Path) -> None:
    T = np.eye(4)
    T[:3, :3] = Rotation.from_euler("xyz", [10, -20, 30], degrees=True).as_matrix()
    T[:3, 3] = [1.205, -0.808, 0.524]
    from_rows = tmp_path / "m"
    from_rows.mkdir()
    d = _kuka_folder(from_rows, T)
    sys.path.insert(0, str(SCRIPT.parent))
    try:
        import handeye_sets_io as io
    finally:
        sys.path.pop(0)
    ds = io.read_set("kuka", d)
    np.testing.assert_allclose(ds.T_base_tool0[0], T, atol=1e-9)
    assert ds.board == io.Board("chessboard", 28, 17, 0.020)

    T_mm = T.copy()
    T_mm[:3, 3] *= 1000.0
    bad = tmp_path / "mm"
    bad.mkdir()
    res = _run("convert", "kuka", str(_kuka_folder(bad, T_mm)), "-o", str(tmp_path / "o2"))
    assert res.returncode == 2
    assert "RobotPosesVec.txt row 1: not a 4 x 4 pose in metres" in res.stderr
    assert "Traceback" not in res.stderr
    assert not (tmp_path / "o2").exists()


def _board_image(cols: int, rows: int, side_px: int = 40, margin_px: int = 60) -> np.ndarray:
    """A chessboard of (cols + 1) x (rows + 1) squares, dark square at the top-left."""
    h, w = (rows + 1) * side_px + 2 * margin_px, (cols + 1) * side_px + 2 * margin_px
    img = np.full((h, w), 255, np.uint8)
    for i in range(rows + 1):
        for j in range(cols + 1):
            if (i + j) % 2 == 0:
                y, x = margin_px + i * side_px, margin_px + j * side_px
                img[y : y + side_px, x : x + side_px] = 30
    return img


def test_corner_order_is_the_same_physical_order_after_a_half_turn() -> None:
    sys.path.insert(0, str(SCRIPT.parent))
    try:
        import handeye_opencv_baseline as cvb
        from handeye_sets_io import Board
    finally:
        sys.path.pop(0)
    board = Board("chessboard", 9, 6, 0.02)
    img = _board_image(9, 6)
    turned = np.ascontiguousarray(img[::-1, ::-1])
    a, _ = cvb.detect_chessboard(img, board)
    b, _ = cvb.detect_chessboard(turned, board)
    assert a is not None and b is not None
    a, b = a.reshape(-1, 2), b.reshape(-1, 2)
    h, w = img.shape
    b_in_img = np.stack([w - 1 - b[:, 0], h - 1 - b[:, 1]], axis=1)
    np.testing.assert_allclose(b_in_img, a, atol=0.5)
    # the dark square diagonally beyond corner 0 is the board's dark top-left square
    assert np.linalg.norm(a[0] - [60 + 40, 60 + 40]) < 1.5
    # and corners handed over in the other order are put back, with the reversal reported
    pts = a.reshape(-1, 1, 2).astype(np.float32)
    back, reversed_ = cvb._canonical_order(img, pts[::-1].copy(), board)
    assert reversed_
    np.testing.assert_array_equal(back, pts)
    same, reversed_ = cvb._canonical_order(img, pts, board)
    assert not reversed_
    np.testing.assert_array_equal(same, pts)
