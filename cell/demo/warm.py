"""The demo's worker processes, started and warmed while the tours are planned.

The simulated head's pairs are rendered and detected in worker processes
(:mod:`cell.camera.workers`). A worker's first pair of each kind costs it seconds: the compiled
kernels loaded, the surface texture and the noise bank drawn, the rays and the plate's
surroundings of each camera computed. Paid in the middle of the calibration tour, that time
competes with the renders for the two cores; paid here, it fills the core that planning leaves
idle. :func:`warm_sim_worker` renders and detects one throwaway scene of each kind the demo
renders (the plate, a survey view, a hole stop with markers) with the simulated head; the caches
it fills are pure functions of their inputs, so every later image is the same bytes.
"""

from __future__ import annotations

from functools import partial

import numpy as np

from cell.camera import cell_stereo
from cell.camera.workers import start_workers
from cell.config import CellConfig
from cell.sim.camera import true_head
from cell.sim.world import WorldOptions
from measure import StereoCalibration
from measure.synth import RenderOptions, render_hole_pair
from measure.synth.marker_draw import MarkerPatch
from measure.synth.markers import render_markers_pair
from measure.synth.targets import render_target_pair
from measure.target import TargetSpec

#: where the throwaway scenes are (m, left camera frame): the plate's centre, the survey's
#: markers and the hole (the demo's stand-offs)
PLATE_STANDOFF_M = 0.3
SURVEY_STANDOFF_M = 0.6
HOLE_STANDOFF_M = 0.25


def start_demo_workers(cell: CellConfig, world: WorldOptions, workers: int = 2) -> bool:
    """Start the process's ``workers`` (:func:`cell.camera.workers.start_workers`), each warmed
    for the simulated head of ``world`` (the cell's head off its calibration as the truth
    draws it); False when they run already."""
    truth = world.truth
    stereo = cell_stereo(cell)
    if truth is not None:
        stereo = true_head(stereo, truth.calibration_sigma_scale, truth.seed)
    target = cell.calibration_target
    spec = target.target_spec() if target is not None else None
    return start_workers(workers, partial(warm_sim_worker, stereo, spec, RenderOptions()))


def warm_sim_worker(
    stereo: StereoCalibration, spec: TargetSpec | None, render: RenderOptions
) -> None:
    """Render and detect one scene of each kind the demo renders (the results are dropped)."""
    from cell.calibration.capture.capture import detect_target
    from measure.markers.detect import detect_markers

    if spec is not None:
        pts = spec.object_points()
        T = np.eye(4)
        T[:3, 3] = [0.0, 0.0, PLATE_STANDOFF_M] - 0.5 * (pts.min(axis=0) + pts.max(axis=0))
        plate = render_target_pair(stereo, spec, T, seed=0)
        detect_target(plate.left, spec, stereo.K_left, stereo.dist_left, 4.0)
    markers = _markers(SURVEY_STANDOFF_M, 0.010)
    survey = render_markers_pair(stereo, markers, render, 0)
    detect_markers(survey.left, stereo.K_left, stereo.dist_left)
    hole = render_hole_pair(stereo, [0.0, 0.0, HOLE_STANDOFF_M], [0.0, 0.0, -1.0], 0.008, render,
                            0, markers=_markers(HOLE_STANDOFF_M, 0.005)[:2])  # fmt: skip
    detect_markers(hole.left, stereo.K_left, stereo.dist_left)


def _markers(standoff_m: float, diameter_m: float) -> list[MarkerPatch]:
    """Four markers facing the head at ``standoff_m``, around the view axis."""
    codes = (1, 2, 3, 4)
    out = []
    for k, code in enumerate(codes):
        a = 0.5 * np.pi * k + 0.4
        c = np.array([0.25 * standoff_m * np.cos(a), 0.2 * standoff_m * np.sin(a), standoff_m])
        out.append(MarkerPatch(code, c, np.array([0.0, 0.0, -1.0]), diameter_m))
    return out
