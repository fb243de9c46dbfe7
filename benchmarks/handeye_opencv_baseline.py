"""Plain OpenCV on a hand-eye data set: detect the board, calibrate the intrinsics (when the set
ships none), ``solvePnP`` per view, then ``calibrateHandEye`` with each of its five methods and
``calibrateRobotWorldHandEye`` with both of its; score every answer on the same views.

Score of an answer ``T_tool0_camera`` (``X``): the reprojection RMS (px) over every corner of
every used view, with the board in the base ``T_base_board`` fitted to that ``X`` by
least squares on the same reprojection error (SciPy ``least_squares``, 6 parameters), so an
answer that gives no board pose (``calibrateHandEye``) is scored like one that does; and ViSP's
consistency residual (the spread of ``T_base_tool0_i X T_camera_board_i`` about its mean,
degrees and millimetres), which its tutorial prints for its own answer.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np
from scipy.optimize import least_squares
from scipy.spatial.transform import Rotation

from handeye_sets_io import Board, pose_matrix

HAND_EYE_METHODS = {
    "TSAI": cv2.CALIB_HAND_EYE_TSAI,
    "PARK": cv2.CALIB_HAND_EYE_PARK,
    "HORAUD": cv2.CALIB_HAND_EYE_HORAUD,
    "ANDREFF": cv2.CALIB_HAND_EYE_ANDREFF,
    "DANIILIDIS": cv2.CALIB_HAND_EYE_DANIILIDIS,
}
RWHE_METHODS = {
    "SHAH": cv2.CALIB_ROBOT_WORLD_HAND_EYE_SHAH,
    "LI": cv2.CALIB_ROBOT_WORLD_HAND_EYE_LI,
}

_CRIT = (cv2.TERM_CRITERIA_EPS | cv2.TERM_CRITERIA_COUNT, 50, 1e-4)


def board_points(board: Board) -> np.ndarray:
    """Corner positions on the board (N, 3, m), OpenCV's row-by-row order."""
    jj, ii = np.meshgrid(np.arange(board.cols), np.arange(board.rows))
    xy = np.stack([jj.ravel(), ii.ravel()], axis=1) * board.pitch_m
    return np.concatenate([xy, np.zeros((len(xy), 1))], axis=1).astype(np.float32)


def _canonical_order(gray: np.ndarray, pts: np.ndarray, board: Board) -> tuple[np.ndarray, bool]:
    """Reverse the corners when the detector returned them rotated by 180°.

    A board with an even and an odd inner-corner count is not symmetric under a half turn:
    of the two outer squares at corner 0, the one diagonally beyond it and the one beside it
    along the first row, the diagonal one is dark in one ordering and light in the other.
    Returns the corners with it dark, and whether they were reversed.
    """
    c = pts.reshape(-1, 2)
    if (board.cols + board.rows) % 2 == 0:
        return pts, False  # symmetric board: no colour tells the orders apart
    hi = [gray.shape[1] - 1, gray.shape[0] - 1]

    def level(p: np.ndarray) -> int:
        x, y = np.clip(np.round(p).astype(int), 0, hi)
        return int(gray[y, x])

    up = c[0] - c[board.cols]  # one square outward, across the first row
    diagonal = c[0] + 0.5 * (up + c[0] - c[1])
    beside = c[0] + 0.5 * (up + c[1] - c[0])
    if level(diagonal) > level(beside):
        return pts[::-1].copy(), True
    return pts, False


def detect_chessboard(gray: np.ndarray, board: Board) -> tuple[np.ndarray | None, bool]:
    """OpenCV's classic detector (then the sector-based one), sub-pixel, canonical order."""
    size = (board.cols, board.rows)
    flags = cv2.CALIB_CB_ADAPTIVE_THRESH | cv2.CALIB_CB_NORMALIZE_IMAGE
    ok, pts = cv2.findChessboardCorners(gray, size, flags=flags)
    if ok:
        pts = cv2.cornerSubPix(gray, pts, (5, 5), (-1, -1), _CRIT)
    else:
        ok, pts = cv2.findChessboardCornersSB(gray, size, flags=cv2.CALIB_CB_NORMALIZE_IMAGE)
        if not ok:
            return None, False
    return _canonical_order(gray, pts.astype(np.float32), board)


def detect_charuco(gray: np.ndarray, board: Board) -> tuple[np.ndarray | None, np.ndarray | None]:
    """ChArUco corners (DICT_5X5_100, ``cols+1`` × ``rows+1`` squares) and their ids."""
    d = cv2.aruco.getPredefinedDictionary(cv2.aruco.DICT_5X5_100)
    cb = cv2.aruco.CharucoBoard(
        (board.cols + 1, board.rows + 1), board.pitch_m, 0.75 * board.pitch_m, d
    )
    corners, ids, _, _ = cv2.aruco.CharucoDetector(cb).detectBoard(gray)
    if ids is None or len(ids) < 6:
        return None, None
    return corners.astype(np.float32), ids.ravel()


@dataclass
class Views:
    """Used views: image names, object and image points, ``T_base_tool0`` and what was dropped."""

    names: list[str]
    obj: list[np.ndarray]
    img: list[np.ndarray]
    T_base_tool0: list[np.ndarray]
    dropped: list[tuple[str, str]]
    flipped: list[str]
    size_wh: tuple[int, int]


def collect_views(rows: list[tuple[str, np.ndarray]], folder, board: Board) -> Views:
    """Detect the board in each ``(image name, T_base_tool0)`` row's image under ``folder``."""
    v = Views([], [], [], [], [], [], (0, 0))
    obj_all = board_points(board)
    for name, T in rows:
        gray = cv2.imread(str(folder / name), cv2.IMREAD_GRAYSCALE)
        if gray is None:
            v.dropped.append((name, "unreadable"))
            continue
        v.size_wh = (gray.shape[1], gray.shape[0])
        if board.pattern == "charuco":
            pts, ids = detect_charuco(gray, board)
            obj = None if ids is None else obj_all[ids]
        else:
            pts, flipped = detect_chessboard(gray, board)
            obj = obj_all
            if flipped:
                v.flipped.append(name)
        if pts is None:
            v.dropped.append((name, "board not found"))
            continue
        v.names.append(name)
        v.obj.append(obj)
        v.img.append(pts.reshape(-1, 1, 2))
        v.T_base_tool0.append(T)
    return v


def calibrate_intrinsics(v: Views) -> tuple[np.ndarray, np.ndarray, float]:
    """``calibrateCamera`` (k1, k2, p1, p2, k3) on the used views: K, dist, RMS (px)."""
    rms, K, dist, _, _ = cv2.calibrateCamera(v.obj, v.img, v.size_wh, None, None)
    return K, dist.ravel(), float(rms)


def camera_board_poses(v: Views, K: np.ndarray, dist: np.ndarray) -> list[np.ndarray]:
    """``T_camera_board`` per view by ``solvePnP`` (iterative)."""
    out = []
    for obj, img in zip(v.obj, v.img, strict=True):
        ok, rvec, tvec = cv2.solvePnP(obj, img, K, dist, flags=cv2.SOLVEPNP_ITERATIVE)
        if not ok:
            raise RuntimeError("solvePnP failed on a view whose board was found")
        out.append(pose_matrix(cv2.Rodrigues(rvec)[0], tvec))
    return out


def opencv_answers(v: Views, T_cam_board: list[np.ndarray]) -> dict[str, dict]:
    """Each method's ``T_tool0_camera`` (and ``T_base_board`` for the robot-world ones)."""
    Rg = [T[:3, :3] for T in v.T_base_tool0]
    tg = [T[:3, 3:] for T in v.T_base_tool0]
    Rc = [T[:3, :3] for T in T_cam_board]
    tc = [T[:3, 3:] for T in T_cam_board]
    out: dict[str, dict] = {}
    for name, m in HAND_EYE_METHODS.items():
        try:
            R, t = cv2.calibrateHandEye(Rg, tg, Rc, tc, method=m)
        except cv2.error as exc:  # a method that fails says so; the others still run
            out[name] = {"X": None, "base_board": None, "error": str(exc).strip().splitlines()[-1]}
            continue
        out[name] = {"X": pose_matrix(R, t), "base_board": None}
    inv_g = [np.linalg.inv(T) for T in v.T_base_tool0]
    for name, m in RWHE_METHODS.items():
        try:
            R_bw, t_bw, R_gc, t_gc = cv2.calibrateRobotWorldHandEye(
                Rc, tc, [T[:3, :3] for T in inv_g], [T[:3, 3:] for T in inv_g], method=m
            )
        except cv2.error as exc:
            out[name] = {"X": None, "base_board": None, "error": str(exc).strip().splitlines()[-1]}
            continue
        out[name] = {
            "X": np.linalg.inv(pose_matrix(R_gc, t_gc)),
            "base_board": np.linalg.inv(pose_matrix(R_bw, t_bw)),
        }
    return out


def is_valid(T: np.ndarray) -> bool:
    """Finite, a proper rotation."""
    if T is None:
        return False
    R = T[:3, :3]
    return bool(
        np.all(np.isfinite(T))
        and abs(np.linalg.det(R) - 1) < 1e-3
        and np.allclose(R.T @ R, np.eye(3), atol=1e-3)
    )


def difference(Ta: np.ndarray, Tb: np.ndarray) -> tuple[float, float]:
    """Translation (mm) and rotation (deg) between two poses."""
    dt = float(np.linalg.norm(Ta[:3, 3] - Tb[:3, 3])) * 1e3
    dR = Rotation.from_matrix(Ta[:3, :3].T @ Tb[:3, :3]).magnitude()
    return dt, float(np.degrees(dR))


def _project(v: Views, X: np.ndarray, T_base_board: np.ndarray, K, dist) -> np.ndarray:
    res = []
    Xi = np.linalg.inv(X)
    for obj, img, T in zip(v.obj, v.img, v.T_base_tool0, strict=True):
        T_cb = Xi @ np.linalg.inv(T) @ T_base_board
        p, _ = cv2.projectPoints(obj, cv2.Rodrigues(T_cb[:3, :3])[0], T_cb[:3, 3], K, dist)
        res.append((p - img).reshape(-1))
    return np.concatenate(res)


def board_in_base(v: Views, X: np.ndarray, T_cam_board: list[np.ndarray]) -> np.ndarray:
    """Mean of ``T_base_tool0_i X T_camera_board_i`` (chordal rotation mean, mean translation)."""
    Ts = [T @ X @ C for T, C in zip(v.T_base_tool0, T_cam_board, strict=True)]
    R = Rotation.from_matrix(np.array([T[:3, :3] for T in Ts])).mean().as_matrix()
    return pose_matrix(R, np.mean([T[:3, 3] for T in Ts], axis=0))


def reprojection_rms(
    v: Views, X: np.ndarray, T_base_board: np.ndarray, K, dist, refit: bool = True
) -> tuple[float, np.ndarray]:
    """RMS (px) over all corners; ``refit`` re-fits ``T_base_board`` to ``X`` first."""
    if refit:
        r0 = Rotation.from_matrix(T_base_board[:3, :3]).as_rotvec()

        def fun(p: np.ndarray) -> np.ndarray:
            Tb = pose_matrix(Rotation.from_rotvec(p[:3]).as_matrix(), p[3:])
            return _project(v, X, Tb, K, dist)

        sol = least_squares(fun, np.concatenate([r0, T_base_board[:3, 3]]), method="lm")
        T_base_board = pose_matrix(Rotation.from_rotvec(sol.x[:3]).as_matrix(), sol.x[3:])
    r = _project(v, X, T_base_board, K, dist)
    return float(np.sqrt(np.mean(r.reshape(-1, 2) ** 2) * 2)), T_base_board


def consistency(v: Views, X: np.ndarray, T_cam_board: list[np.ndarray]) -> tuple[float, float]:
    """ViSP's residual: mean rotation (deg) and translation (mm) of each view's board-in-base
    estimate ``T_base_tool0_i X T_camera_board_i`` from their mean."""
    mean = board_in_base(v, X, T_cam_board)
    d = [difference(T @ X @ C, mean) for T, C in zip(v.T_base_tool0, T_cam_board, strict=True)]
    return float(np.mean([r for _, r in d])), float(np.mean([t for t, _ in d]))


def _pose_params(T: np.ndarray) -> np.ndarray:
    return np.concatenate([Rotation.from_matrix(T[:3, :3]).as_rotvec(), T[:3, 3]])


def _params_pose(p: np.ndarray) -> np.ndarray:
    return pose_matrix(Rotation.from_rotvec(p[:3]).as_matrix(), p[3:])


def joint_refinement(
    v: Views, X0: np.ndarray, T_base_board0: np.ndarray, K, dist
) -> tuple[np.ndarray, np.ndarray]:
    """``X`` and ``T_base_board`` together by least squares on the reprojection error of all
    corners (SciPy, Levenberg-Marquardt, intrinsics and robot poses fixed): the reprojection
    formulation of AX = ZB, a reference for sets whose authors publish no transform."""

    def fun(p: np.ndarray) -> np.ndarray:
        return _project(v, _params_pose(p[:6]), _params_pose(p[6:]), K, dist)

    sol = least_squares(
        fun, np.concatenate([_pose_params(X0), _pose_params(T_base_board0)]), method="lm"
    )
    return _params_pose(sol.x[:6]), _params_pose(sol.x[6:])


def subset(v: Views, keep: list[int]) -> Views:
    """The views at ``keep``."""
    pick = lambda xs: [xs[i] for i in keep]  # noqa: E731
    return Views(
        pick(v.names),
        pick(v.obj),
        pick(v.img),
        pick(v.T_base_tool0),
        v.dropped,
        v.flipped,
        v.size_wh,
    )


def jackknife(v: Views, T_cam_board: list[np.ndarray], K, dist) -> dict[str, np.ndarray]:
    """Leave-one-view-out standard deviations of PARK's and the reprojection answer's
    ``T_tool0_camera``: ``[σx, σy, σz]`` (mm) and ``[σ about x, y, z]`` (deg, of the rotation
    vector of each estimate relative to their mean), from ``(n-1)/n Σ (θ_i - θ̄)²``."""
    est: dict[str, list[np.ndarray]] = {"PARK": [], "reproj-LM": []}
    n = len(v.names)
    for i in range(n):
        keep = [j for j in range(n) if j != i]
        w, T = subset(v, keep), [T_cam_board[j] for j in keep]
        X0 = opencv_answers(w, T)["PARK"]["X"]
        est["PARK"].append(X0)
        est["reproj-LM"].append(joint_refinement(w, X0, board_in_base(w, X0, T), K, dist)[0])
    out = {}
    for name, Xs in est.items():
        R_mean = Rotation.from_matrix(np.array([X[:3, :3] for X in Xs])).mean()
        rv = np.array([(R_mean.inv() * Rotation.from_matrix(X[:3, :3])).as_rotvec() for X in Xs])
        t = np.array([X[:3, 3] for X in Xs]) * 1e3
        f = (n - 1) / n
        out[name] = np.concatenate(
            [
                np.sqrt(f * ((t - t.mean(0)) ** 2).sum(0)),
                np.degrees(np.sqrt(f * ((rv - rv.mean(0)) ** 2).sum(0))),
            ]
        )
    return out
