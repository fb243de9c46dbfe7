"""What the cell calibration observes: per view the target's corners and the arm's pose.

A view is one robot stop: the joints ``q_rad`` (URDF order, rad) when the arm's kinematic
errors are to be estimated, or the flange pose ``T_base_tool0`` measured elsewhere; the
target's features in the left image and, for a stereo head, in the right image (pixels,
OpenCV's convention, in :meth:`measure.target.TargetSpec.object_points` order), ``None`` for
an image where the target was not found.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from cell.calibration.errors import CalibrationDataError
from measure.calibration import StereoCalibration
from measure.target import TargetSpec

Array = NDArray[np.float64]


@dataclass(frozen=True, eq=False)
class Intrinsics:
    """One camera: 3x3 matrix ``K`` (px), OpenCV distortion ``dist``, ``image_size`` (w, h)."""

    K: Array
    dist: Array
    image_size: tuple[int, int]


@dataclass(frozen=True, eq=False)
class Cameras:
    """The head: the left camera, and for a stereo head the right one with the stereo
    calibration's ``T_left_right`` (4x4, m) as the starting value of the extrinsics.

    ``source`` names the calibration file (stereo.json or a FileStorage file).
    """

    left: Intrinsics
    right: Intrinsics | None = None
    T_left_right: Array | None = None
    source: str = "<memory>"

    @property
    def stereo(self) -> bool:
        """Whether the head has a right camera."""
        return self.right is not None

    @classmethod
    def from_stereo(cls, st: StereoCalibration) -> Cameras:
        """Both cameras of a ``stereo.json`` (``T_left_right`` = inverse of its ``R, T``)."""
        T_right_left = np.eye(4)
        T_right_left[:3, :3], T_right_left[:3, 3] = st.R, st.T
        return cls(
            left=Intrinsics(st.K_left.copy(), st.dist_left.copy(), tuple(st.image_size)),
            right=Intrinsics(st.K_right.copy(), st.dist_right.copy(), tuple(st.image_size)),
            T_left_right=np.linalg.inv(T_right_left),
            source=st.source,
        )


@dataclass(frozen=True, eq=False)
class CalibrationView:
    """One view: a label for messages, the arm's pose and the corners seen (px)."""

    name: str
    corners_left_px: Array | None
    corners_right_px: Array | None = None
    q_rad: Array | None = None
    T_base_tool0: Array | None = None


@dataclass(frozen=True, eq=False)
class CalibrationObservations:
    """All views of one calibration, the target and the head that saw it.

    ``source`` names the data (a poses CSV, a tour) for error messages.
    """

    views: tuple[CalibrationView, ...]
    target: TargetSpec
    cameras: Cameras
    source: str = "<memory>"

    def __post_init__(self) -> None:
        n = len(self.target.object_points())
        has_q = [v.q_rad is not None for v in self.views]
        if any(has_q) and not all(has_q):
            raise CalibrationDataError(self.source, "some views give joints and others do not")
        for v in self.views:
            if v.q_rad is None and v.T_base_tool0 is None:
                raise CalibrationDataError(self.source, "neither joints nor flange pose", v.name)
            if v.q_rad is not None:
                q = np.asarray(v.q_rad, float)
                if q.shape != (6,) or not np.all(np.isfinite(q)):
                    raise CalibrationDataError(
                        self.source, "joints must be 6 finite numbers", v.name
                    )
            if v.T_base_tool0 is not None:
                T = np.asarray(v.T_base_tool0, float)
                if T.shape != (4, 4) or not np.all(np.isfinite(T)):
                    raise CalibrationDataError(
                        self.source, "flange pose must be a finite 4x4", v.name
                    )
            for side, c in (("left", v.corners_left_px), ("right", v.corners_right_px)):
                if c is not None and np.shape(c) != (n, 2):
                    raise CalibrationDataError(
                        self.source, f"{side} corners must be ({n}, 2), got {np.shape(c)}", v.name
                    )
            if v.corners_right_px is not None and not self.cameras.stereo:
                raise CalibrationDataError(self.source, "right corners for a mono head", v.name)

    @property
    def has_joints(self) -> bool:
        """Whether the views give joints (then the kinematic terms can be estimated)."""
        return bool(self.views) and self.views[0].q_rad is not None

    def joints(self) -> Array:
        """Joints of every view (V, 6) (rad)."""
        return np.array([np.asarray(v.q_rad, float) for v in self.views])

    def corners(self, side: str) -> tuple[Array, NDArray[np.bool_]]:
        """Corners (V, N, 2) of one camera (NaN where unseen) and the seen mask (V,)."""
        n = len(self.target.object_points())
        out = np.full((len(self.views), n, 2), np.nan)
        seen = np.zeros(len(self.views), dtype=bool)
        for i, v in enumerate(self.views):
            c = v.corners_left_px if side == "left" else v.corners_right_px
            if c is not None:
                out[i], seen[i] = np.asarray(c, float), True
        return out, seen
