"""Stereo hole measurement: calibration, sub-pixel edges, triangulation, circle fit.

Public API (all lengths in metres, results in the LEFT camera optical frame):

- :func:`measure_hole` → :class:`HoleMeasurement` (options: :class:`MeasureOptions`)
- :func:`fit_circle_3d` → :class:`Circle3D`
- :class:`StereoCalibration` (``load``/``save`` of ``stereo.json``), :func:`head_frame`
- :func:`measure_hole_opencv` — the OpenCV-only baseline used by the benchmark
- :mod:`measure.synth` — the synthetic stereo renderer with exact ground truth
- :class:`MeasurementError` and its subclasses in :mod:`measure.errors`
"""

from measure.baseline import BaselineResult, measure_hole_opencv
from measure.calibration import StereoCalibration
from measure.circle import Circle3D, fit_circle_3d
from measure.errors import MeasurementError
from measure.head import convergence_distance_m, head_frame
from measure.pipeline import measure_hole
from measure.result import HoleMeasurement, MeasureOptions

__all__ = [
    "BaselineResult",
    "Circle3D",
    "HoleMeasurement",
    "MeasureOptions",
    "MeasurementError",
    "StereoCalibration",
    "convergence_distance_m",
    "fit_circle_3d",
    "head_frame",
    "measure_hole",
    "measure_hole_opencv",
]
