"""Synthetic stereo renderer: a hole in a machined metal plate, with exact ground truth.

Used by the tests, the benchmarks and the cell simulator. Public API:

- :func:`standard_stereo` — the benchmark head (2 × 2448×2048, 3.45 µm, 16 mm, 100 mm
  baseline, toed in to meet at 250 mm, small distortion).
- :func:`hole_in_view` — place a hole at the standoff with a given tilt.
- :func:`render_hole_pair` / :func:`render_reference_pair` — images plus :class:`HoleTruth`.
- :func:`render_target_pair` — calibration plate images (chessboard, asymmetric circles).
- :class:`MarkerPatch` — a reference marker in a scene (``render_hole_pair(..., markers=...)``);
  :func:`render_markers_pair` — a survey view of markers (:mod:`measure.synth.markers`).
"""

from measure.synth.heads import (
    STANDARD_STANDOFF_M,
    hole_in_view,
    standard_stereo,
    toed_in_stereo,
)
from measure.synth.marker_draw import MarkerPatch
from measure.synth.markers import MarkerRender, render_markers_pair
from measure.synth.render import (
    HoleTruth,
    RenderOptions,
    StereoRender,
    render_hole_pair,
    render_reference_pair,
)

__all__ = [
    "STANDARD_STANDOFF_M",
    "HoleTruth",
    "MarkerPatch",
    "MarkerRender",
    "RenderOptions",
    "StereoRender",
    "hole_in_view",
    "render_hole_pair",
    "render_markers_pair",
    "render_reference_pair",
    "standard_stereo",
    "toed_in_stereo",
]
