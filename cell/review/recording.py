"""Rerun recording of a run: ``run.rrd`` in the run directory, optionally a live viewer too.

What is logged (entity paths; 3D in the cell frame, m; the URDF's root frame ``base_link`` is
attached to the scene root by ``T_cell_base``):

- ``<robot model>``: the arm from its URDF, by Rerun's URDF importer (static); joint transforms
  (named frames) on ``transforms`` at every stop
  (timeline ``run_time``, the controller clock in s) and along the planned trajectory
  (timeline ``tour_time``, s, every 0.1 s).
- ``cell/obstacles/*``: part and environment obstacles; ``cell/holes``: nominal holes and normals.
- ``tour/path``: planned TCP path; ``tour/stops``: the stops.
- ``run/tcp``: TCP position at each stop; ``run/hole/points``: triangulated edge points;
  ``run/hole/circle``: the fitted circle; ``camera/left|right``: the image region of each pair
  with its edge points (filled ones in orange) and fitted ellipse drawn over it.
- ``plots/deviation/*`` (um), ``plots/temperature/*`` (degC): time series; ``run/state``: the
  run state as a state timeline.
- ``referencing/markers``: the surveyed markers (static, labelled by id); at each referenced
  stop ``run/head/resected`` and ``run/head/arm`` (the left camera where the markers and where
  the arm put it), ``run/head/markers`` (the markers the stop used) and
  ``plots/referencing/arm_disagreement`` (um).
- ``plots/uncertainty/U_position|U_diameter`` (um, k = 2) and ``plots/budget/<component>`` (the
  position's standard uncertainty per component, um): time series; ``run/decision``: the ISO
  14253-1 decision of each hole as a log line; ``run/decisions/<hole>``: the hole coloured by
  it (green proven, orange inconclusive, red nonconforming).

An explicit default blueprint lays it out (3D view, the two cameras, plots, state timeline).
"""

from __future__ import annotations

import logging
from pathlib import Path

import numpy as np
import rerun as rr
import rerun.blueprint as rrb

from cell.config import CellConfig
from cell.records.hole_result import HoleResult
from planner import Tour
from robots import Shape

log = logging.getLogger(__name__)

#: pixels of margin around the measured region of interest in the logged image crops
CROP_MARGIN_PX = 20


def blueprint() -> rrb.Blueprint:
    """The default layout of a run recording."""
    return rrb.Blueprint(
        rrb.Horizontal(
            rrb.Spatial3DView(
                name="cell",
                origin="/",
                contents=["+ /**", "- /camera/**", "- /plots/**", "- /run/state"],
            ),
            rrb.Vertical(
                rrb.Horizontal(
                    rrb.Spatial2DView(name="left camera", origin="/camera/left"),
                    rrb.Spatial2DView(name="right camera", origin="/camera/right"),
                ),
                rrb.TimeSeriesView(name="deviation (um)", origin="/plots/deviation"),
                rrb.TimeSeriesView(name="U, k=2 (um)", origin="/plots/uncertainty"),
                rrb.TimeSeriesView(name="temperatures (degC)", origin="/plots/temperature"),
                rrb.StateTimelineView(name="run state", origin="/run/state"),
            ),
            column_shares=[3, 2],
        ),
        collapse_panels=True,
    )


class Recorder:
    """Logs one run. ``create`` opens the file (and a viewer with ``spawn``/``connect``)."""

    def __init__(self, rec: rr.RecordingStream, cell: CellConfig, tour: Tour) -> None:
        self.rec = rec
        self.cell = cell
        self.tour = tour
        self.arm = cell.build_arm()
        self.T_view_cell = np.eye(4)  # the 3D scene is logged in the cell frame
        self.urdf = rr.urdf.UrdfTree.from_file_path(self.arm.urdf_path)
        self.joints = {j.name: j for j in self.urdf.joints()}

    @classmethod
    def create(
        cls,
        path: str | Path,
        cell: CellConfig,
        tour: Tour,
        spawn: bool = False,
        connect: str | None = None,
    ) -> Recorder:
        """Record to ``path``; also to a spawned viewer or the one at ``connect`` (gRPC URL)."""
        rec = rr.RecordingStream("holecell", recording_id=None)
        sinks: list = [rr.FileSink(str(path))]
        if spawn:
            rec.spawn(connect=False)
            sinks.append(rr.GrpcSink())
        elif connect:
            sinks.append(rr.GrpcSink(connect))
        rec.set_sinks(*sinks, default_blueprint=blueprint())
        self = cls(rec, cell, tour)
        self._static()
        return self

    def close(self) -> None:
        """Flush and close the recording."""
        self.rec.flush()
        self.rec.disconnect()

    # --- static scene -----------------------------------------------------------------------
    def _p(self, p_cell: np.ndarray) -> np.ndarray:
        p = np.asarray(p_cell, float).reshape(-1, 3)
        return p @ self.T_view_cell[:3, :3].T + self.T_view_cell[:3, 3]

    def _static(self) -> None:
        rec = self.rec
        rec.log_file_from_path(self.arm.urdf_path, static=True)
        # attach the URDF's root frame to the scene root (the cell frame) at the base pose
        T = np.asarray(self.cell.T_cell_base(), float)
        root = rr.Transform3D(
            translation=T[:3, 3],
            quaternion=rr.Quaternion(xyzw=_quat_xyzw(T[:3, :3])),
            parent_frame="tf#/",
            child_frame=self.urdf.root_link().name,
        )
        rec.log("transforms/base", root, static=True)
        for i, shape in enumerate(self.cell.obstacle_shapes()):
            self._shape(f"cell/obstacles/{i}_{shape.name}", shape)
        holes = self.cell.holes_in_cell()
        pos = self._p(np.array([h.position_m for h in holes]))
        nrm = np.array([h.normal for h in holes]) @ self.T_view_cell[:3, :3].T
        rec.log(
            "cell/holes",
            rr.Points3D(pos, radii=0.003, labels=[h.id for h in holes], colors=[80, 160, 255]),
            static=True,
        )
        rec.log("cell/holes/normals", rr.Arrows3D(origins=pos, vectors=0.03 * nrm), static=True)
        traj = self.tour.trajectory[:: max(1, round(0.02 / self.tour.dt))]
        tcp = self._p(np.array([self.arm.fk(q, "tcp")[:3, 3] for q in traj]))
        rec.log("tour/path", rr.LineStrips3D([tcp], radii=0.001, colors=[255, 200, 0]), static=True)
        stops = self._p(
            np.array([self.arm.fk(np.array(s.q), "tcp")[:3, 3] for s in self.tour.stops])
        )
        rec.log(
            "tour/stops",
            rr.Points3D(stops, radii=0.004, colors=[255, 120, 0], labels=self.tour.hole_order),
            static=True,
        )
        step = max(1, round(0.1 / self.tour.dt))
        for i in range(0, len(self.tour.trajectory), step):
            rec.set_time("tour_time", duration=i * self.tour.dt)
            self._joints(self.tour.trajectory[i])

    def _shape(self, path: str, s: Shape) -> None:
        T = self.T_view_cell @ np.asarray(s.T, float)
        quat = rr.Quaternion(xyzw=_quat_xyzw(T[:3, :3]))
        kind = s.kind
        if kind == "box":
            arch = rr.Boxes3D(
                half_sizes=[np.asarray(s.size) / 2],
                centers=[T[:3, 3]],
                quaternions=[quat],
                colors=[150, 150, 150],
            )
        elif kind in ("cylinder", "capsule"):
            arch = rr.Cylinders3D(
                lengths=[s.size[1]],
                radii=[s.size[0]],
                centers=[T[:3, 3]],
                quaternions=[quat],
                colors=[150, 150, 150],
            )
        elif s.mesh is not None:  # a CAD mesh obstacle, vertices moved into the view frame
            v = s.mesh.vertices @ T[:3, :3].T + T[:3, 3]
            arch = rr.Mesh3D(
                vertex_positions=v, triangle_indices=s.mesh.faces, albedo_factor=[150, 150, 150]
            )
        else:
            arch = rr.Ellipsoids3D(
                half_sizes=[[s.size[0]] * 3], centers=[T[:3, 3]], colors=[150, 150, 150]
            )
        self.rec.log(path, arch, static=True)

    def _joints(self, q: np.ndarray) -> None:
        for name, value in zip(self.arm.joint_names, q, strict=True):
            self.rec.log(
                "transforms", self.joints[name].compute_transform(float(value), clamp=False)
            )

    # --- during the run ---------------------------------------------------------------------
    def state(self, state: str) -> None:
        """The run state changed."""
        self.rec.log("run/state", rr.StateChange(state=state))

    def markers(self, ids: tuple[str, ...], positions_cell: np.ndarray) -> None:
        """The surveyed marker network (static)."""
        self._marker_ids = {m: k for k, m in enumerate(ids)}
        self._marker_pos = self._p(np.asarray(positions_cell, float))
        self.rec.log("referencing/markers", rr.Points3D(self._marker_pos, radii=0.003,
                     colors=[255, 255, 255], labels=list(ids)), static=True)  # fmt: skip

    def _located(self, located) -> None:
        """A stop's resected head beside the arm's, the markers it used, their difference."""
        rec, r = self.rec, located.resection
        if not located.referenced:
            rec.log("run/event", rr.TextLog(f"{located.view.view_id}: not referenced "
                                            f"({r.reason})", level="WARN"))  # fmt: skip
            return
        for name, T, color in (("resected", r.T_cell_left, [0, 200, 255]),
                               ("arm", located.T_cell_left_arm, [255, 160, 0])):  # fmt: skip
            rec.log(f"run/head/{name}", rr.Points3D(self._p(T[:3, 3]), radii=0.004,
                                                    colors=[color]))  # fmt: skip
        rec.log("plots/referencing/arm_disagreement", rr.Scalars(located.disagreement_m * 1e6))
        idx = [self._marker_ids[m] for m in r.used if m in getattr(self, "_marker_ids", {})]
        if idx:
            rec.log("run/head/markers", rr.Points3D(self._marker_pos[idx], radii=0.004,
                                                    colors=[0, 255, 120]))  # fmt: skip

    def hole(self, result: HoleResult, meas, pair, status, T_cell_left: np.ndarray,
             located=None) -> None:  # fmt: skip
        """Log one stop: joints, temperatures, images with edges and ellipse, 3D points,
        circle, deviations; ``located``: the stop's referencing, if the run is referenced."""
        rec = self.rec
        rec.set_time("run_time", duration=float(status.time_s))
        self._joints(status.q_rad)
        tcp = self._p(self.arm.fk(status.q_rad, "tcp")[:3, 3])
        rec.log("run/tcp", rr.Points3D(tcp, radii=0.005, colors=[0, 220, 0]))
        for i, t in enumerate(status.temperatures_c):
            rec.log(f"plots/temperature/s{i + 1}", rr.Scalars(float(t)))
        if located is not None:
            self._located(located)
        if meas is None:
            rec.log("run/event", rr.TextLog(f"{result.hole_id}: {result.reason}", level="WARN"))
            return
        # ISO 1101 position: the zone's diameter, 2 x the in-plane distance (fixture frame)
        rec.log("plots/deviation/position", rr.Scalars(2 * result.position_deviation_m * 1e6))
        rec.log("plots/deviation/diameter", rr.Scalars(result.diameter_deviation_m * 1e6))
        self._budget(result)
        self._images(meas, pair)
        T = self.T_view_cell @ T_cell_left
        pts = meas.points_m[meas.inliers] @ T[:3, :3].T + T[:3, 3]
        rec.log("run/hole/points", rr.Points3D(pts, radii=0.0002, colors=[0, 200, 255]))
        rec.log(
            "run/hole/circle",
            rr.LineStrips3D([_circle(meas, T)], radii=0.0003, colors=[255, 0, 80]),
        )

    def _budget(self, result: HoleResult) -> None:
        """U (k = 2) and every component of the hole's budget as time series (um), the
        decision as a log line, and the hole's nominal position coloured by it."""
        if result.U_position_m is None:
            return
        rec = self.rec
        rec.log("plots/uncertainty/U_position", rr.Scalars(2 * result.U_position_m * 1e6))
        rec.log("plots/uncertainty/U_diameter", rr.Scalars(result.U_diameter_m * 1e6))
        for c in (result.budget or {}).get("components", []):
            rec.log(f"plots/budget/{c['name']}", rr.Scalars(c["u_position_m"] * 1e6))
        level = {"conforming": "INFO", "inconclusive": "WARN", "nonconforming": "ERROR"}
        rec.log("run/decision", rr.TextLog(
            f"{result.hole_id}: {result.decision or 'no tolerance'} (position ⌀"
            f"{2 * result.position_deviation_m * 1e6:.1f} µm ± {2 * result.U_position_m * 1e6:.1f}"
            " µm in the fixture frame, "
            f"diameter {result.diameter_deviation_m * 1e6:+.1f} µm ± "
            f"{result.U_diameter_m * 1e6:.1f} µm, k = 2)",
            level=level.get(result.decision or "", "INFO")))  # fmt: skip
        color = {
            "conforming": [46, 125, 50],
            "inconclusive": [239, 143, 0],
            "nonconforming": [198, 40, 40],
        }.get(result.decision or "", [117, 117, 117])
        hole = {h.id: h for h in self.cell.holes_in_cell()}[result.hole_id]
        rec.log(f"run/decisions/{result.hole_id}",
                rr.Points3D(self._p(hole.position_m), radii=0.006, colors=[color],
                            labels=[f"{result.hole_id} {result.decision or ''}"]))  # fmt: skip

    def _images(self, meas, pair) -> None:
        m = meas
        sides = (
            ("left", pair.left, m.roi_left, m.edges_left_px, m.filled_left, m.ellipse_left),
            ("right", pair.right, m.roi_right, m.edges_right_px, m.filled_right, m.ellipse_right),
        )
        for side, img, roi, edges, filled, ellipse in sides:
            x, y, w, h = roi
            x0, y0 = max(0, x - CROP_MARGIN_PX), max(0, y - CROP_MARGIN_PX)
            x1 = min(img.shape[1], x + w + CROP_MARGIN_PX)
            y1 = min(img.shape[0], y + h + CROP_MARGIN_PX)
            off = np.array([x0, y0], float)
            self.rec.log(f"camera/{side}/image", rr.Image(np.ascontiguousarray(img[y0:y1, x0:x1])))
            e = np.asarray(edges, float) - off
            colors = np.where(np.asarray(filled, bool)[:, None], [255, 140, 0], [0, 255, 0])
            self.rec.log(f"camera/{side}/edges", rr.Points2D(e, radii=0.6, colors=colors))
            strip = rr.LineStrips2D([_ellipse(ellipse) - off], colors=[255, 0, 80])
            self.rec.log(f"camera/{side}/ellipse", strip)


def _ellipse(e, n: int = 120) -> np.ndarray:
    (cx, cy), (a1, a2), ang = e
    t = np.linspace(0, 2 * np.pi, n)
    c, s = np.cos(np.radians(ang)), np.sin(np.radians(ang))
    x, y = 0.5 * a1 * np.cos(t), 0.5 * a2 * np.sin(t)
    return np.stack([cx + c * x - s * y, cy + s * x + c * y], axis=1)


def _circle(meas, T: np.ndarray, n: int = 120) -> np.ndarray:
    nrm = np.asarray(meas.normal, float)
    u = np.cross(nrm, [1.0, 0.0, 0.0] if abs(nrm[0]) < 0.9 else [0.0, 1.0, 0.0])
    u /= np.linalg.norm(u)
    v = np.cross(nrm, u)
    t = np.linspace(0, 2 * np.pi, n)[:, None]
    pts = meas.center_m + meas.radius_m * (np.cos(t) * u + np.sin(t) * v)
    return pts @ T[:3, :3].T + T[:3, 3]


def _quat_xyzw(R: np.ndarray) -> list[float]:
    from scipy.spatial.transform import Rotation

    return Rotation.from_matrix(R).as_quat().tolist()
