"""Candidate calibration views: every feasible way for the arm to show the board to both cameras.

A view direction is the board's inward normal (the TCP z axis along the board's +z, into the
printed face) tilted by each
of ``tilts_deg`` toward ``azimuths`` directions in the board plane; the TCP sits at each of
``distances`` × ``standoff_m`` from the board's centre along it, rolled about it every
``roll_step_deg``, and shifted sideways in its own x-y plane by each of ``offsets`` ×
``standoff_m`` (the board then lies off the image centre: over a set of views its features
cover the whole image). A pose is kept when, in **both** cameras:

- every feature is in front of the camera, at a depth within ``depth_range`` × ``standoff_m``
  (the head's depth of field around its working distance);
- every feature projects inside the image, ``margin_frac`` of the width away from its border
  (through the cell's lens model, :class:`planner.calibration.board.StereoModel`);
- the line of sight to the board's centre is at most ``max_tilt_deg`` from the board normal,
  on the printed side.

Each kept pose's IK solutions within the joint limits are grouped by arm geometry (values 2π
apart put the arm in the same place and see the board the same way); each collision-free
geometry is one candidate, its 2π variants the choices the tour's sequencer may pick from.
The arm and head are not checked for hiding the board from the cameras: the cameras look
away from the arm, and a tilt of at most ``max_tilt_deg`` keeps the head's own body out of
the line of sight.
"""

from __future__ import annotations

import logging
from collections import Counter
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray
from scipy.spatial import ConvexHull, QhullError

from planner.calibration.board import Board, StereoModel
from planner.errors import NoCalibrationViewError, PlanningError
from planner.protocols import ArmLike
from robots.transforms import invert

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class CandidateOptions:
    """How candidate views are sampled and what makes one feasible (see module docstring).

    Tilts and angles in degrees; ``distances`` and ``depth_range`` relative to ``standoff_m``;
    ``offsets`` (x, y) relative to ``standoff_m``; ``margin_frac`` relative to the image width.
    """

    tilts_deg: tuple[float, ...] = (0.0, 20.0, 35.0, 50.0)
    azimuths: int = 8
    roll_step_deg: float = 45.0
    distances: tuple[float, ...] = (0.9, 1.0, 1.15)
    offsets: tuple[tuple[float, float], ...] = (
        (0.0, 0.0), (0.1, 0.1), (-0.1, 0.1), (0.1, -0.1), (-0.1, -0.1),
    )  # fmt: skip
    depth_range: tuple[float, float] = (0.7, 1.4)
    margin_frac: float = 0.02
    max_tilt_deg: float = 55.0

    def __post_init__(self) -> None:
        if not self.tilts_deg or any(not 0 <= t < 90 for t in self.tilts_deg):
            raise PlanningError(f"tilts_deg {self.tilts_deg}: each must lie in [0, 90)")
        if self.azimuths < 1 or not 0 < self.roll_step_deg <= 360:
            raise PlanningError("azimuths must be >= 1 and roll_step_deg in (0, 360]")
        if not self.offsets or any(len(o) != 2 for o in self.offsets):
            raise PlanningError(f"offsets {self.offsets}: expected (x, y) pairs")
        if not self.distances or min(self.distances) <= 0:
            raise PlanningError(f"distances {self.distances}: must be positive")
        lo, hi = self.depth_range
        if not 0 < lo < hi:
            raise PlanningError(f"depth_range {self.depth_range}: expected 0 < low < high")
        if not 0 <= self.margin_frac < 0.5 or not 0 < self.max_tilt_deg < 90:
            raise PlanningError("margin_frac must lie in [0, 0.5), max_tilt_deg in (0, 90)")


@dataclass(frozen=True)
class Candidates:
    """Feasible views, one row each (m, rad, px; cell frame unless named).

    ``T_cell_tcp`` (m, 4, 4); ``q`` (m, 6) the representative configuration (the variant
    nearest home); ``variants[i]`` (k_i, 6) every configuration of that arm geometry within
    limits; ``branch`` (m,) IK branch; ``T_left_target`` / ``T_right_target`` (m, 4, 4) the
    board in each camera; ``uv_left`` / ``uv_right`` (m, n, 2) the features' pixels;
    ``tilt_rad`` (m,) the larger line-of-sight angle to the board normal of the two cameras;
    ``coverage`` (m, 2) the features' convex hull as a share of each image; ``refused``
    counts the sampled poses or geometries left out, by reason.
    """

    T_cell_tcp: NDArray[np.float64]
    q: NDArray[np.float64]
    variants: list[NDArray[np.float64]]
    branch: NDArray[np.int64]
    T_left_target: NDArray[np.float64]
    T_right_target: NDArray[np.float64]
    uv_left: NDArray[np.float64]
    uv_right: NDArray[np.float64]
    tilt_rad: NDArray[np.float64]
    coverage: NDArray[np.float64]
    refused: dict[str, int] = field(default_factory=dict)

    def __len__(self) -> int:
        return len(self.q)

    def subset(self, rows: list[int] | NDArray[np.int64]) -> Candidates:
        """The candidates at ``rows``, in that order."""
        r = np.asarray(rows, dtype=np.int64)
        return Candidates(
            self.T_cell_tcp[r], self.q[r], [self.variants[i] for i in r], self.branch[r],
            self.T_left_target[r], self.T_right_target[r], self.uv_left[r], self.uv_right[r],
            self.tilt_rad[r], self.coverage[r], dict(self.refused),
        )  # fmt: skip


def _basis(z: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    ref = np.array([1.0, 0.0, 0.0]) if abs(z[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    x = ref - z * (ref @ z)
    x /= np.linalg.norm(x)
    return x, np.cross(z, x)


def sample_poses(board: Board, standoff_m: float, o: CandidateOptions) -> NDArray[np.float64]:
    """Every sampled ``T_cell_tcp`` (p, 4, 4) looking at the board's centre (module docstring)."""
    T = np.asarray(board.T_cell_target, dtype=float)
    centre = T[:3, :3] @ board.centre_target + T[:3, 3]
    inward = T[:3, 2]  # into the printed face (planner.calibration.board)
    bx, by = T[:3, 0], T[:3, 1]
    dirs = []
    for tilt in np.radians(o.tilts_deg):
        n_az = 1 if tilt == 0 else o.azimuths
        for k in range(n_az):
            phi = 2 * np.pi * k / n_az
            side = np.cos(phi) * bx + np.sin(phi) * by
            dirs.append(np.cos(tilt) * inward + np.sin(tilt) * side)
    rolls = np.radians(np.arange(0.0, 360.0 - 1e-9, o.roll_step_deg))
    poses = []
    for z in dirs:
        z = z / np.linalg.norm(z)
        x0, y0 = _basis(z)
        for d in o.distances:
            for roll in rolls:
                c, s = np.cos(roll), np.sin(roll)
                R = np.column_stack((c * x0 + s * y0, -s * x0 + c * y0, z))
                for ox, oy in o.offsets:
                    P = np.eye(4)
                    P[:3, :3] = R
                    shift = ox * R[:, 0] + oy * R[:, 1]
                    P[:3, 3] = centre - d * standoff_m * z + standoff_m * shift
                    poses.append(P)
    return np.array(poses)


def hull_vertices(points_target: NDArray[np.float64]) -> NDArray[np.int64]:
    """Indices of the board's features on their convex hull (board plane), in order. A camera
    in front of the plane keeps that hull and its order (a perspective map preserves convexity;
    the lens's distortion bends the edges by a fraction of a pixel)."""
    return np.asarray(ConvexHull(np.asarray(points_target)[:, :2]).vertices, dtype=np.int64)


def hull_share(
    uv: NDArray[np.float64], image_size: tuple[int, int], vertices: NDArray[np.int64]
) -> float:
    """The features' convex hull area (``uv[vertices]``, the shoelace formula) as a share of
    the image area."""
    x, y = uv[vertices, 0], uv[vertices, 1]
    area = 0.5 * abs(float(x @ np.roll(y, -1) - y @ np.roll(x, -1)))
    return area / (image_size[0] * image_size[1])


def _camera_view(
    T_cell_cam: NDArray[np.float64],
    board: Board,
    project: object,
    standoff_m: float,
    o: CandidateOptions,
    image_size: tuple[int, int],
) -> tuple[str | None, NDArray[np.float64], NDArray[np.float64], float]:
    """(refusal or None, T_cam_target, pixels, line-of-sight tilt rad) of one camera."""
    T_cam_target = invert(T_cell_cam) @ np.asarray(board.T_cell_target, dtype=float)
    P = np.asarray(board.points_target) @ T_cam_target[:3, :3].T + T_cam_target[:3, 3]
    lo, hi = o.depth_range
    if P[:, 2].min() < lo * standoff_m or P[:, 2].max() > hi * standoff_m:
        return "out of the depth of field", T_cam_target, np.zeros((0, 2)), 0.0
    sight = T_cam_target[:3, :3] @ board.centre_target + T_cam_target[:3, 3]
    into_plate = T_cam_target[:3, 2]  # the printed face looks along -z
    cos = float((sight @ into_plate) / np.linalg.norm(sight))
    tilt = float(np.arccos(np.clip(cos, -1.0, 1.0)))
    if tilt > np.radians(o.max_tilt_deg):
        return "board seen too obliquely or from behind", T_cam_target, np.zeros((0, 2)), tilt
    uv = np.asarray(project(P), dtype=np.float64).reshape(-1, 2)  # type: ignore[operator]
    w, h = image_size
    m = o.margin_frac * w
    inside = (uv[:, 0] >= m) & (uv[:, 0] <= w - 1 - m) & (uv[:, 1] >= m) & (uv[:, 1] <= h - 1 - m)
    if not np.all(inside & np.all(np.isfinite(uv), axis=1)):
        return "board not wholly in the image", T_cam_target, uv, tilt
    return None, T_cam_target, uv, tilt


def _geometries(solutions: NDArray[np.float64]) -> list[NDArray[np.int64]]:
    """Row groups of ``solutions`` that put the arm in the same place (equal modulo 2π)."""
    wrapped = np.round((solutions + np.pi) % (2 * np.pi) - np.pi, 7)
    _, inverse = np.unique(wrapped, axis=0, return_inverse=True)
    return [np.flatnonzero(inverse.ravel() == g) for g in range(int(inverse.max()) + 1)]


def _in_collision_each(arm: ArmLike, Q: NDArray[np.float64]) -> NDArray[np.bool_]:
    """``arm.in_collision`` of each row of ``Q``, in one batch call where the arm offers it."""
    each = getattr(arm, "in_collision_each", None)
    if each is not None:
        return np.asarray(each(Q), dtype=bool).reshape(len(Q))
    return np.array([arm.in_collision(q) for q in Q], dtype=bool)


def candidate_views(
    arm: ArmLike,
    board: Board,
    stereo: StereoModel,
    standoff_m: float,
    home_q: NDArray[np.float64],
    options: CandidateOptions | None = None,
) -> Candidates:
    """Every feasible view of ``board`` (module docstring); :class:`NoCalibrationViewError`
    when there is none. ``standoff_m``: the head's working distance (m); ``home_q`` (rad)
    picks each geometry's representative variant (the nearest)."""
    o = options or CandidateOptions()
    home = np.asarray(home_q, dtype=float)
    refused: Counter[str] = Counter()
    kept: list[tuple] = []
    for T_cell_tcp in sample_poses(board, standoff_m, o):
        views = []
        for T_tcp_cam, project in (
            (stereo.T_tcp_left, stereo.project_left),
            (stereo.T_tcp_right, stereo.project_right),
        ):
            why, T_ct, uv, tilt = _camera_view(
                T_cell_tcp @ T_tcp_cam, board, project, standoff_m, o, stereo.image_size
            )
            if why is not None:
                refused[why] += 1
                break
            views.append((T_ct, uv, tilt))
        if len(views) < 2:
            continue
        result = arm.ik(T_cell_tcp)
        if not result.ok:
            refused[result.reason or "no IK solution"] += 1
            continue
        for rows in _geometries(np.asarray(result.solutions, dtype=float)):
            variants = np.asarray(result.solutions, dtype=float)[rows]
            rep = variants[int(np.argmin(np.abs(variants - home).sum(axis=1)))]
            kept.append((T_cell_tcp, rep, variants, int(result.branches[rows[0]]), views))
    if kept:
        hit = _in_collision_each(arm, np.array([k[1] for k in kept]))
        refused["arm or head in collision"] += int(hit.sum())
        kept = [k for k, h in zip(kept, hit, strict=True) if not h]
    if not kept:
        raise NoCalibrationViewError(board.name, dict(refused))
    size = stereo.image_size
    try:
        vertices = hull_vertices(board.points_target)
    except QhullError as exc:
        raise PlanningError(f"{board.name}: the features do not span the plane") from exc
    out = Candidates(
        T_cell_tcp=np.array([k[0] for k in kept]),
        q=np.array([k[1] for k in kept]),
        variants=[k[2] for k in kept],
        branch=np.array([k[3] for k in kept], dtype=np.int64),
        T_left_target=np.array([k[4][0][0] for k in kept]),
        T_right_target=np.array([k[4][1][0] for k in kept]),
        uv_left=np.array([k[4][0][1] for k in kept]),
        uv_right=np.array([k[4][1][1] for k in kept]),
        tilt_rad=np.array([max(k[4][0][2], k[4][1][2]) for k in kept]),
        coverage=np.array([[hull_share(k[4][c][1], size, vertices) for c in (0, 1)] for k in kept]),
        refused=dict(refused),
    )
    log.info("%s: %d candidate views (%s refused)", board.name, len(out), dict(refused))
    return out
