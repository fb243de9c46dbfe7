"""Options and result of a stereo hole measurement."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from measure.contour import Ellipse


@dataclass(frozen=True)
class MeasureOptions:
    """How :func:`measure.measure_hole` works. Defaults are the benchmarked best method.

    Attributes:
        edge_method: ``"parabola"`` (Devernay gradient-maximum, default) or ``"linear"``
            (published linear interpolation of gray values).
        circle_cost: ``"orthogonal"`` (true orthogonal distance, default) or ``"published"``.
        smoothing_sigma_px: Gaussian smoothing before the gradient (pixels).
        curvature_correction: move edge points outward by σ²κ/2, the shift of gradient
            maxima on a blurred curved edge (σ measured from the edge profile).
        slope_correction: move each gradient-maximum edge point back by the shift that a
            brightness slope beside the edge causes, (s₊ − s₋) σ² / A (the bore wall's
            ramp inside a tilted rim; :mod:`measure.slope`; ``"parabola"`` edges only).
        arc_step_px: spacing of the lines through the centroid, in pixels of arc.
        short_gap_px: gaps up to this length (px) are filled along the contour and used in
            the fit; longer gaps are filled from the image ellipse, reported, not used.
        use_long_fills: also fit points filled over long gaps (the published method does).
        min_epipolar_angle_deg: drop contour samples whose tangent is closer than this to the
            epipolar direction.
        robust: robust circle fit with rejection (see :func:`measure.fit_circle_3d`).
        near_side_max_angle_deg: with ``robust``, edge points a camera sees over the rim
            at more than this angle to the hole axis are kept only where they agree with a
            circle fitted to the others (see :mod:`measure.nearside`); ``None`` disables.
        size_tolerance: relative diameter deviation from ``expected_diameter_m`` that is an error.
        suspect_fraction: status ``"suspect"`` when more than this fraction of the contour
            was filled or rejected.
        suspect_rms_m, suspect_rms_px: status ``"suspect"`` when the fit's RMS residual
            exceeds both ``suspect_rms_m`` (metres) and ``suspect_rms_px`` left-camera pixels
            at the hole's depth (a good fit is a few µm on the standard head, about 0.05 px;
            a fit through the wrong edge or a broken contour is tenths of a pixel).
        suspect_rim_mismatch: status ``"suspect"`` when the left and right edges used were
            found at gray levels (inside, outside) that differ by more than this fraction
            of the contrast: the two images may show different edges.
        suspect_epipolar_px: status ``"suspect"`` when the top or bottom rows of the two
            rectified contours differ by more than this (pixels): both are tangent to the
            same epipolar planes when the calibration fits the images.
    """

    edge_method: str = "parabola"
    circle_cost: str = "orthogonal"
    smoothing_sigma_px: float = 0.5
    curvature_correction: bool = True
    slope_correction: bool = True
    arc_step_px: float = 1.0
    short_gap_px: float = 4.0
    use_long_fills: bool = False
    min_epipolar_angle_deg: float = 20.0
    robust: bool = True
    near_side_max_angle_deg: float | None = 25.0
    size_tolerance: float = 0.2
    suspect_fraction: float = 0.3
    suspect_rms_m: float = 25e-6
    suspect_rms_px: float = 0.3
    suspect_rim_mismatch: float = 0.5
    suspect_epipolar_px: float = 1.5

    @classmethod
    def published(cls) -> MeasureOptions:
        """The published method as described: linear interpolation, the published cost, all
        filled points used, no curvature correction, no outlier rejection."""
        return cls(
            edge_method="linear",
            circle_cost="published",
            use_long_fills=True,
            curvature_correction=False,
            slope_correction=False,
            robust=False,
        )


@dataclass(frozen=True)
class RimChoice:
    """Which edge was measured as the hole's rim (per image: left, right).

    Attributes:
        polarity: ``"dark"`` (the hole interior is darker than what surrounds it) or
            ``"bright"`` (a through-hole against a lit background).
        surround: ``"surface"`` when just outside the rim is the part's surface, ``"ring"``
            when it is a ring of another brightness (a grommet, washer, lip or chamfer):
            the measured edge is then the bore's rim inside that ring, not the ring's
            outer edge.
        diameter_px: equivalent diameter of the hole region (pixels).
        levels: how many of the detector's threshold-ladder levels gave this region.
        inside_level, outside_level, ring_level, surface_level: median gray levels
            (fraction of full scale) just inside the rim, in a ring just outside it (3 … 7
            px), in a ring 5 … 20 % of the diameter outside it, and of the surface (an
            annulus one to one and a half diameters from the centre). ``surround`` is
            "ring" when the outside or ring level differs from the surface level by more
            than 15 % of the rim's contrast plus 2 % of full scale, in both images.
        depth_m: depth of the region centroids (left frame, metres), from their disparity.
    """

    polarity: str
    surround: str
    diameter_px: tuple[float, float]
    levels: tuple[int, int]
    inside_level: tuple[float, float]
    outside_level: tuple[float, float]
    ring_level: tuple[float, float]
    surface_level: tuple[float, float]
    depth_m: float

    def describe(self) -> str:
        """One line for people: which edge was used."""
        where = (
            "inside a ring of another brightness (grommet, washer, lip or chamfer)"
            if self.surround == "ring"
            else "against the surface"
        )
        return (
            f"rim of the {self.polarity} interior {where}, ⌀{self.diameter_px[0]:.0f} / "
            f"{self.diameter_px[1]:.0f} px (left / right)"
        )

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready form."""
        return {
            "polarity": self.polarity,
            "surround": self.surround,
            "diameter_px": [float(v) for v in self.diameter_px],
            "levels": [int(v) for v in self.levels],
            "inside_level": [float(v) for v in self.inside_level],
            "outside_level": [float(v) for v in self.outside_level],
            "ring_level": [float(v) for v in self.ring_level],
            "surface_level": [float(v) for v in self.surface_level],
            "depth_m": float(self.depth_m),
            "description": self.describe(),
        }


@dataclass(frozen=True)
class HoleMeasurement:
    """A measured hole, in the LEFT camera optical frame, SI units.

    Attributes:
        status: ``"ok"``, or ``"suspect"`` when much of the edge was filled or rejected,
            the fit RMS is high, or the two images' rims differ (``suspect_reasons`` says
            which; thresholds in :class:`MeasureOptions`).
        center_m: circle centre (3,). normal: unit axis pointing toward the camera (3,).
        radius_m: circle radius. rms_m: RMS orthogonal residual of the fitted 3-D points.
        n_points / n_rejected / n_filled: 3-D points used by the fit, rejected as outliers,
            and contour samples filled over broken edges (both images).
        cov_center_radius: 4×4 covariance of (cx, cy, cz, r) from the fit (m²).
        timings: seconds per stage (wall clock); ``time_s`` the total. ``cpu_timings``:
            the CPU seconds the calling thread spent per stage (``time.thread_time``; on a
            shared machine the wall clock includes waiting for a core).
        edges_left_px / edges_right_px: contour samples (N, 2) in each image (distorted
            pixels); ``filled_left`` / ``filled_right`` mark the filled ones.
        ellipse_left / ellipse_right: robust image ellipses, ``cv2.fitEllipse`` style
            ``((cx, cy), (axis1, axis2), angle_deg)`` with full axis lengths.
        points_m: triangulated edge points (K, 3, left frame); ``inliers`` (K,) those kept.
        roi_left / roi_right: the regions of interest used, ``(x, y, w, h)``.
        rim: which edge was measured (:class:`RimChoice`); ``suspect_reasons`` why the
            status is ``"suspect"`` (empty when ``"ok"``).
    """

    status: str
    center_m: np.ndarray
    normal: np.ndarray
    radius_m: float
    rms_m: float
    n_points: int
    n_rejected: int
    n_filled: int
    cov_center_radius: np.ndarray
    timings: dict[str, float]
    time_s: float
    edges_left_px: np.ndarray
    edges_right_px: np.ndarray
    filled_left: np.ndarray
    filled_right: np.ndarray
    ellipse_left: Ellipse
    ellipse_right: Ellipse
    points_m: np.ndarray
    inliers: np.ndarray
    roi_left: tuple[int, int, int, int]
    roi_right: tuple[int, int, int, int]
    options: MeasureOptions = field(default_factory=MeasureOptions)
    rim: RimChoice | None = None
    suspect_reasons: tuple[str, ...] = ()
    cpu_timings: dict[str, float] = field(default_factory=dict)

    @property
    def diameter_m(self) -> float:
        """Circle diameter (metres)."""
        return 2.0 * self.radius_m

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready summary (the ``holecell measure --json`` object, without images)."""
        return {
            "status": self.status,
            "center_m": [float(v) for v in self.center_m],
            "normal": [float(v) for v in self.normal],
            "radius_m": float(self.radius_m),
            "diameter_m": float(self.diameter_m),
            "rms_m": float(self.rms_m),
            "n_points": int(self.n_points),
            "n_rejected": int(self.n_rejected),
            "n_filled": int(self.n_filled),
            "rms_um": float(self.rms_m * 1e6),
            "suspect_reasons": list(self.suspect_reasons),
            "rim": self.rim.to_dict() if self.rim is not None else None,
            "cov_center_radius_m2": self.cov_center_radius.tolist(),
            "time_s": float(self.time_s),
            "timings_s": {k: float(v) for k, v in self.timings.items()},
            "cpu_timings_s": {k: float(v) for k, v in self.cpu_timings.items()},
        }
