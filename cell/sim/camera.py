"""The simulated stereo head: renders each capture from the simulator's truth.

At the moment of the trigger it takes the controller's actual joints and the simulation time,
computes the TRUE camera pose (true base, D-H errors and thermal drift, true head:
:class:`cell.sim.true_geometry.TrueGeometry`), finds the true hole or reference target in
front of the head, and renders the pair with :func:`measure.synth.render_hole_pair` (a reference
target with :func:`measure.synth.render_reference_pair`). A missing hole renders the bare surface.
With the view axis on the calibration plate (at its true pose) in front of any hole, or with no
hole in view and the plate anywhere in either image (a real camera sees it wherever it is), it
renders the plate with :func:`measure.synth.targets.render_target_pair`.
The reference markers in front of the head (at their true places,
:attr:`cell.sim.world.SimWorld.markers`) are drawn into hole scenes and reference scenes; a view
with markers and neither a hole nor the plate (a survey view) renders them with
:func:`measure.synth.markers.render_markers_pair`. A hole scene's surface (a plane across the
whole image) hides the markers more than 0.1 m behind it; otherwise the part does not hide a
marker, and a view of the plate shows no marker.

:meth:`SimCamera.snapshot` takes the exposure now and returns the rendering as a picklable
function (the scene, the head and the seed), so that a survey renders its views in worker
processes while the arm moves on; :meth:`SimCamera.capture` is the snapshot rendered at once.
"""

from __future__ import annotations

import zlib
from collections.abc import Callable
from dataclasses import dataclass
from functools import partial

import numpy as np

from cell.camera import StereoPair
from cell.sim.controller import SimController
from cell.sim.world import SimWorld, TrueHole
from cell.uncertainty.calibration import (
    N_PARAMETERS,
    default_uncertainty,
    parameter_sigmas,
    perturbed,
)
from cell.uncertainty.repeatability import sigma_per_axis_m
from measure import StereoCalibration
from measure.synth import RenderOptions, render_hole_pair, render_reference_pair
from measure.synth.markers import MarkerPatch, render_markers_pair
from measure.synth.targets import plate_box, render_target_pair
from robots.transforms import invert


def true_head(stereo: StereoCalibration, scale: float, seed: int) -> StereoCalibration:
    """The head as it really is: the calibration ``stereo`` with every parameter off by a
    normal draw of ``scale`` times its stated (or the default) standard deviation."""
    if scale <= 0:
        return stereo
    unc = stereo.uncertainty or default_uncertainty(stereo)
    rng = np.random.default_rng([seed, 0xCA11B])
    return perturbed(stereo, scale * rng.normal(0.0, 1.0, N_PARAMETERS) * parameter_sigmas(unc))


#: a feature counts as "in front of the head" within this distance of the view axis (m)
VIEW_AXIS_TOL_M = 0.02
#: the calibration plate is rendered when the view axis meets it this far from the head, or
#: when its centre is this far from the head and it shows in either image (m)
TARGET_RANGE_M = (0.05, 1.0)


@dataclass(frozen=True)
class CaptureTruth:
    """What was really in front of the head at a capture (for tests and the demo's error)."""

    feature_id: str | None
    kind: str  # "hole", "reference", "missing", "target" or "none"
    T_cell_left: np.ndarray
    center_cell_m: np.ndarray | None
    diameter_m: float | None


class SimCamera:
    """A :class:`cell.camera.CameraBackend` rendering from a :class:`SimWorld`."""

    def __init__(
        self,
        world: SimWorld,
        controller: SimController,
        stereo: StereoCalibration,
        missing_holes: tuple[str, ...] = (),
        render: RenderOptions | None = None,
        seed: int = 0,
    ) -> None:
        self.world = world
        self.controller = controller
        self.stereo = stereo  # the calibration file: what the runner measures with
        tr = world.truth
        self.true_stereo = true_head(stereo, tr.calibration_sigma_scale, tr.seed)
        self._rep_sigma_m = sigma_per_axis_m(tr.repeatability_rp_m)
        self.geometry = world.true_geometry(stereo)
        self.missing = set(missing_holes)
        self.render = render or RenderOptions()
        self._T_head_left = self.geometry.T_tcp_left
        self._seed = seed
        self.captures = 0
        self.last_truth: CaptureTruth | None = None
        self.references = {
            r.id: TrueHole(r.id, np.array(r.position, float), np.array(r.normal, float), r.diameter)
            for r in world.cell.reference_targets
        }

    def computing(self):
        """The simulation's clock held while the computer works on a pair
        (:func:`cell.camera.backend.computing`)."""
        return self.world.clock.held()

    def capture(self) -> StereoPair:
        """Render the pair the head sees now (an exposure takes no simulation time)."""
        with self.world.clock.held():
            return self._snapshot(self.world.clock.now())()

    def snapshot(self) -> Callable[[], StereoPair]:
        """The exposure now, rendered later: a picklable function that renders the pair the
        head sees at this moment (what :meth:`capture` returns), so that the rendering can run
        in another process while the arm moves on. The capture is counted and
        :attr:`last_truth` set now; the same snapshots render the same pairs wherever and in
        whatever order they are rendered."""
        with self.world.clock.held():
            return self._snapshot(self.world.clock.now())

    def _snapshot(self, t: float) -> Callable[[], StereoPair]:
        T_cell_tcp = self.world.true_T_cell_tcp(self.controller.q_rad(), t)
        kind, feature = self._in_view(invert(T_cell_tcp @ self._T_head_left))
        s_target = self._target_distance(T_cell_tcp)
        if s_target is not None and (feature is None or s_target < _depth(T_cell_tcp, feature)):
            kind, feature = "target", None  # the plate is in front of whatever lies behind it
        key = "calibration_target" if kind == "target" else feature.id if feature else "none"
        seed = (self._seed * 1_000_003 + zlib.crc32(key.encode())) & 0x7FFFFFFF
        if self._rep_sigma_m > 0:  # the arm's repeatability: this approach's scatter
            rng = np.random.default_rng([self.world.truth.seed, seed, self.captures])
            T_cell_tcp = T_cell_tcp.copy()
            T_cell_tcp[:3, 3] += rng.normal(0.0, self._rep_sigma_m, 3)
        T_cell_left = T_cell_tcp @ self._T_head_left
        T_left_cell = invert(T_cell_left)
        self.captures += 1
        if kind == "target":
            return self._target_scene(T_cell_left, seed)
        surface = None
        if feature is not None:
            surface = (T_left_cell[:3, :3] @ feature.position_m + T_left_cell[:3, 3],
                       T_left_cell[:3, :3] @ feature.normal)  # fmt: skip
        markers = self._marker_patches(T_left_cell, surface)
        if feature is not None and float(T_left_cell[:3, :3] @ feature.normal
                                         @ (T_left_cell[:3, :3] @ feature.position_m
                                            + T_left_cell[:3, 3])) >= 0.0:  # fmt: skip
            feature = None  # seen edge-on or from behind by the left camera: not a hole view
        if feature is None:  # bare surface facing the head, no hole anywhere near the view
            self.last_truth = CaptureTruth(None, "none", T_cell_left, None, None)
            if markers:
                return partial(_render_markers, self.true_stereo, markers, self.render, seed)
            return partial(_render_bare, self.true_stereo)
        c = T_left_cell[:3, :3] @ feature.position_m + T_left_cell[:3, 3]
        n = T_left_cell[:3, :3] @ feature.normal
        if kind == "missing":  # the surface is there, the hole is not: render it far off-view
            u = np.cross(n, [1.0, 0.0, 0.0])
            c = c + 5.0 * u / np.linalg.norm(u)
        self.last_truth = CaptureTruth(
            feature.id, kind, T_cell_left, feature.position_m.copy(), feature.diameter_m
        )
        return partial(_render_hole, kind == "reference", self.true_stereo, c, n,
                       feature.diameter_m, self.render, seed, markers)  # fmt: skip

    def _marker_patches(
        self, T_left_cell: np.ndarray, surface: tuple[np.ndarray, np.ndarray] | None = None
    ) -> list[MarkerPatch]:
        """The true markers facing the head and projecting into (or near) either image, in the
        left camera frame; ``surface`` (a point and its normal, left frame): a hole scene's
        plane, which hides every marker more than :data:`BEHIND_SURFACE_M` behind it."""
        mt = self.world.markers
        if mt is None:
            return []
        R, t = T_left_cell[:3, :3], T_left_cell[:3, 3]
        p_left = mt.true @ R.T + t
        n_left = mt.normals @ R.T
        seen = _in_either_image(self.true_stereo, p_left, n_left)
        if surface is not None:  # the scene's plate spans the whole image
            c, n = surface
            seen &= (p_left - c) @ n > -BEHIND_SURFACE_M
        out = []
        for k in np.flatnonzero(seen):
            out.append(MarkerPatch(int(mt.codes[k]), p_left[k], n_left[k], mt.diameters_m[k]))
        return out

    def _target_distance(self, T_cell_tcp: np.ndarray) -> float | None:
        """How far along the head's view axis it meets the calibration plate's printed face
        from in front (m; the plate's true pose), ``inf`` when the axis misses the plate but
        the plate shows in either image (any hole on the axis then wins), or None: the face
        turned away, out of view or not within ``TARGET_RANGE_M``."""
        T_cell_target = self.world.T_cell_target
        if T_cell_target is None:
            return None
        T = invert(T_cell_target) @ T_cell_tcp  # the head in the board frame
        o, d = T[:3, 3], T[:3, 2]
        if not o[2] < 0:  # the face is z = 0 and faces -z
            return None
        spec = self.world.cell.calibration_target.target_spec()
        lo, hi = spec.plate_bounds()
        if d[2] > 0:
            s = float(-o[2] / d[2])
            p = o + s * d
            inside = lo[0] <= p[0] <= hi[0] and lo[1] <= p[1] <= hi[1]
            if inside and TARGET_RANGE_M[0] <= s <= TARGET_RANGE_M[1]:
                return s
        centre = np.array([0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), 0.0])
        if not TARGET_RANGE_M[0] <= float(np.linalg.norm(centre - o)) <= TARGET_RANGE_M[1]:
            return None
        T_left_target = invert(T_cell_tcp @ self._T_head_left) @ T_cell_target
        T_right_left = np.eye(4)
        T_right_left[:3, :3], T_right_left[:3, 3] = self.true_stereo.R, self.true_stereo.T
        corners = np.array([[x, y, 0.0, 1.0] for x in (lo[0], hi[0]) for y in (lo[1], hi[1])])
        for side, Tc in (("left", T_left_target), ("right", T_right_left @ T_left_target)):
            if np.all((corners @ Tc[2]) <= 0):  # wholly behind this camera
                continue
            if plate_box(self.true_stereo, side, Tc[:3, :3], Tc[:3, 3], spec) is not None:
                return float("inf")
        return None

    def _target_scene(self, T_cell_left: np.ndarray, seed: int) -> Callable[[], StereoPair]:
        """The calibration plate at its true pose in the true head, to render."""
        spec = self.world.cell.calibration_target.target_spec()
        T_left_target = invert(T_cell_left) @ self.world.T_cell_target
        origin = self.world.T_cell_target[:3, 3].copy()
        self.last_truth = CaptureTruth("calibration_target", "target", T_cell_left, origin, None)
        return partial(_render_target, self.true_stereo, spec, T_left_target, seed)

    def _in_view(self, T_left_cell: np.ndarray) -> tuple[str, TrueHole | None]:
        T_head_cell = invert(self._T_head_left) @ T_left_cell
        best: tuple[float, str, TrueHole | None] = (VIEW_AXIS_TOL_M, "none", None)
        candidates = [("hole", h) for h in self.world.holes_at_temperature.values()]
        candidates += [("reference", r) for r in self.references.values()]
        for kind, f in candidates:
            p = T_head_cell[:3, :3] @ f.position_m + T_head_cell[:3, 3]
            lateral = float(np.hypot(p[0], p[1]))
            facing = float((T_head_cell[:3, :3] @ f.normal) @ p) < 0.0  # its face toward us
            if p[2] > 0 and facing and lateral < best[0]:
                best = (lateral, kind, f)
        _, kind, feature = best
        if feature is not None and kind == "hole" and feature.id in self.missing:
            kind = "missing"
        return kind, feature

    def close(self) -> None:
        """Nothing to release."""


#: a hole scene's surface hides the markers more than this far behind it (m): the table and
#: the far side of the frame (T14 lies 0.43 m behind CTL's plane), not the neighbouring faces of
#: the same part (CUL's shared markers lie 62-84 mm behind its plane)
BEHIND_SURFACE_M = 0.1
#: a marker is drawn when seen this close to face-on (rad) by the left camera
MARKER_RENDER_ANGLE_RAD = np.radians(80.0)


def _in_either_image(stereo: StereoCalibration, p_left: np.ndarray, n_left: np.ndarray):
    """Mask (n,) of markers (left camera frame) in front of the head, facing it, whose
    pinhole image lies in (or within 5 % of) the left or the right image."""
    w, h = stereo.image_size
    ok = p_left[:, 2] > 0.05
    to_cam = -p_left / np.maximum(np.linalg.norm(p_left, axis=1, keepdims=True), 1e-12)
    ok &= np.einsum("ij,ij->i", to_cam, n_left) >= np.cos(MARKER_RENDER_ANGLE_RAD)
    R, T = np.asarray(stereo.R, float), np.asarray(stereo.T, float).ravel()
    inside = np.zeros(len(p_left), bool)
    for K, P in ((stereo.K_left, p_left), (stereo.K_right, p_left @ R.T + T)):
        z = np.maximum(P[:, 2], 1e-9)
        uv = (P[:, :2] / z[:, None]) @ np.asarray(K)[:2, :2].T + np.asarray(K)[:2, 2]
        inside |= ((uv[:, 0] > -0.05 * w) & (uv[:, 0] < 1.05 * w) & (uv[:, 1] > -0.05 * h)
                   & (uv[:, 1] < 1.05 * h) & (P[:, 2] > 0.05))  # fmt: skip
    return ok & inside


def _render_markers(stereo: StereoCalibration, markers: list[MarkerPatch],
                    render: RenderOptions, seed: int) -> StereoPair:  # fmt: skip
    pair = render_markers_pair(stereo, markers, render, seed)
    return StereoPair(pair.left, pair.right)


def _render_bare(stereo: StereoCalibration) -> StereoPair:
    pair = render_hole_pair(stereo, [5.0, 0.0, 0.25], [0.0, 0.0, -1.0], 0.01)
    return StereoPair(pair.left, pair.right)


def _render_hole(reference: bool, stereo: StereoCalibration, c: np.ndarray, n: np.ndarray,
                 diameter_m: float, render: RenderOptions, seed: int,
                 markers: list[MarkerPatch]) -> StereoPair:  # fmt: skip
    fn = render_reference_pair if reference else render_hole_pair
    pair = fn(stereo, c, n, diameter_m, render, seed, markers=markers)
    return StereoPair(pair.left, pair.right)


def _render_target(stereo: StereoCalibration, spec, T_left_target: np.ndarray,
                   seed: int) -> StereoPair:  # fmt: skip
    r = render_target_pair(stereo, spec, T_left_target, seed=seed)
    return StereoPair(r.left, r.right)


def _depth(T_cell_head: np.ndarray, feature: TrueHole) -> float:
    """Distance of ``feature`` along the head's view axis (m)."""
    return float((invert(T_cell_head) @ np.append(feature.position_m, 1.0))[2])
