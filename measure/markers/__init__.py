"""Reference markers: circular coded targets (a white dot on black) and their detection.

- :class:`MarkerDesign`, :data:`DEFAULT_DESIGN` — the physical design (ring-coded or with an
  adjacent AprilTag 36h11), in dot diameters (docs/markers.md).
- :func:`detect_markers` — every identified marker in an image: code, sub-pixel ellipse
  centre, its standard deviation.
- :func:`circle_center_bias_px` — the perspective bias of a circle's image centre
  (:func:`circle_center_bias_many_px`: of many circles at once).
"""

from measure.markers.bias import circle_center_bias_many_px, circle_center_bias_px
from measure.markers.design import APRILTAG_DESIGN, DEFAULT_DESIGN, RING_DESIGN, MarkerDesign
from measure.markers.detect import MarkerDetection, detect_markers

__all__ = [
    "APRILTAG_DESIGN",
    "DEFAULT_DESIGN",
    "RING_DESIGN",
    "MarkerDesign",
    "MarkerDetection",
    "circle_center_bias_many_px",
    "circle_center_bias_px",
    "detect_markers",
]
