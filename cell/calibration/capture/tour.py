"""The cell calibration in the cell: run the calibration tour, then one adjustment of all views.

:func:`run_calibration_tour` checks that the tour belongs to the cell and its target, runs it
(:class:`cell.calibration.capture.capture.TourCapture`), refuses a view without the target in
either image (one line naming the view and the detector's reason; nothing is solved), builds
the :class:`cell.calibration.estimate.observations.CalibrationObservations` (joints as
the controller reported them, both cameras with the head's stereo calibration), solves them
(:func:`cell.calibration.estimate.solve.solve_calibration`: refusals of too few views and degenerate
rotations, the rank test, the covariance) and sets the provenance
(:mod:`cell.calibration.file.provenance`) so that a run of another robot, tool, cell or stereo head
refuses the file. :func:`calibrate_cell` returns just the calibration.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field, replace

from cell.calibration.capture.capture import (
    CaptureSettings,
    Progress,
    TourCapture,
    TourCaptures,
)
from cell.calibration.capture.warming import MAX_K, TourWarming, check_warming, tour_warming
from cell.calibration.errors import CalibrationDataError
from cell.calibration.estimate.observations import CalibrationObservations, CalibrationView, Cameras
from cell.calibration.estimate.result import CellCalibration, Provenance
from cell.calibration.estimate.soft_views import DroppedView, is_soft, solve_without
from cell.calibration.estimate.solve import CalibrationResult, SolveOptions, solve_calibration
from cell.calibration.file.provenance import cell_provenance
from cell.camera import CameraBackend
from cell.config import CellConfig
from cell.config.tours import check_tour
from cell.errors import CellError, TourMismatchError
from cell.link.client import ControllerClient
from measure.target import TargetSpec
from planner import TourCellMismatchError, check_tour_for_cell
from planner.calibration import CalibrationTour
from robots.dh import DHTable


@dataclass(frozen=True)
class CalibrateCellOptions:
    """Settings of :func:`calibrate_cell`: the motion and detection (``capture``) and the
    adjustment (``solve``; the stereo extrinsics, the D-H terms and the cameras' intrinsic
    corrections are estimated by default: with the intrinsics taken as exact the TCP error
    after calibration was 43.5 um RMS on seed 0 with 120 views, with them estimated 19.8 um,
    docs/calibration.md)."""

    capture: CaptureSettings = field(default_factory=CaptureSettings)
    solve: SolveOptions = field(default_factory=lambda: SolveOptions(estimate_intrinsics=True))
    max_warming_K: float = MAX_K  # noqa: N815 (unit suffix): cell.calibration.capture.warming


@dataclass(frozen=True, eq=False)
class CellCalibrationRun:
    """What :func:`run_calibration_tour` did: the captures, the observations, the adjustment's
    result (its ``calibration`` is what ``cellcal.json`` holds) and the wall time of the whole
    (s)."""

    captures: TourCaptures
    observations: CalibrationObservations
    result: CalibrationResult
    wall_s: float
    dropped: tuple[DroppedView, ...] = ()
    warming: TourWarming | None = None

    @property
    def calibration(self) -> CellCalibration:
        """The calibration."""
        return self.result.calibration


def tour_target_spec(cell: CellConfig, cal_tour: CalibrationTour, where: str) -> TargetSpec:
    """The cell's target, refused when the tour was planned for another board."""
    t = cell.calibration_target
    if t is None:
        raise CellError(f"cell {cell.name!r}: calibration_target: missing; the cell file must "
                        "place the calibration target to calibrate the cell")  # fmt: skip
    for key, mine in (("pattern", t.pattern), ("cols", t.cols), ("rows", t.rows),
                      ("pitch_m", t.pitch_m)):  # fmt: skip
        theirs = cal_tour.target.get(key)
        if theirs != mine:
            raise CellError(f"{where}: calibration.target.{key} is {theirs!r} but the cell's "
                            f"calibration_target has {mine!r}: plan the tour for this cell "
                            "(holecell plan-calibration)")  # fmt: skip
    return t.target_spec()


def check_calibration_tour(cell: CellConfig, cal_tour: CalibrationTour, where: str) -> TargetSpec:
    """Refuse a calibration tour not planned for ``cell`` (robot model, cell name, SHA-256 of
    the cell file, joint names, trajectory, the board); returns the board."""
    try:
        check_tour_for_cell(cal_tour.tour, cell)
    except TourCellMismatchError as exc:
        raise TourMismatchError(where, exc.field, exc.tour_value, exc.cell_value) from exc
    check_tour(cal_tour.tour, cell, where, reference=True)
    if not cal_tour.tour.stops:
        raise CellError(f"{where}: stops: the calibration tour has no views")
    return tour_target_spec(cell, cal_tour, where)


def observations_of(
    captures: TourCaptures, spec: TargetSpec, cameras: Cameras, source: str,
    strict: bool = False, dropped: list[DroppedView] | None = None,
) -> CalibrationObservations:  # fmt: skip
    """The observations of a tour; a view whose left or right image lacks the target is
    refused naming the view and the reason (the tour plans every view with the whole board in
    both images: a missing board means a wrong target pose or a camera fault, which no
    calibration should silently absorb). A view failing only a quality check (a blurred image)
    is appended to ``dropped`` and left out, unless ``strict``
    (:mod:`cell.calibration.estimate.soft_views`)."""
    views = []
    for v in captures.views:
        soft = None
        for side, pts, why in (("left", v.corners_left_px, v.reason_left),
                               ("right", v.corners_right_px, v.reason_right)):  # fmt: skip
            if pts is None and (side == "left" or cameras.stereo):
                if strict or not is_soft(why):
                    raise CalibrationDataError(source, f"{side} image: {why}; nothing written",
                                               v.id)  # fmt: skip
                soft = soft or DroppedView(v.id, f"{side} image: {why}")
        if soft is not None:
            if dropped is not None:
                dropped.append(soft)
            continue
        right = v.corners_right_px if cameras.stereo else None
        views.append(CalibrationView(v.id, v.corners_left_px, right, q_rad=v.q_rad))
    return CalibrationObservations(tuple(views), spec, cameras, source)


@dataclass(frozen=True, eq=False)
class CapturedTour:
    """A calibration tour driven and detected, not yet solved (:func:`capture_calibration_tour`):
    the captures, the arm's warming, the observations, the views dropped, the nominal D-H
    table, the provenance and when the tour started (``time.perf_counter``)."""

    captures: TourCaptures
    warming: TourWarming | None
    observations: CalibrationObservations
    dropped: tuple[DroppedView, ...]
    dh: DHTable
    provenance: Provenance
    source: str
    t0: float


def run_calibration_tour(
    cell: CellConfig,
    tour: CalibrationTour,
    client: ControllerClient,
    camera: CameraBackend,
    options: CalibrateCellOptions | None = None,
    progress: Progress | None = None,
    source: str = "calibration tour",
) -> CellCalibrationRun:
    """Run ``tour`` on ``client`` (connected), capture with ``camera``, detect, solve
    (:func:`capture_calibration_tour`, then :func:`finish_calibration_tour`).

    Raises :class:`CalibrationDataError` (a view without the target, naming it),
    :class:`cell.calibration.errors.DegenerateCalibrationError` (too few views, degenerate
    rotations, an undetermined hand-eye), :class:`cell.link.motion.RunFaultError` (a controller
    fault: the arm is stopped) or :class:`CellError` (a tour of another cell or board)."""
    o = options or CalibrateCellOptions()
    captured = capture_calibration_tour(cell, tour, client, camera, o, progress, source)
    report = progress or (lambda event, data: None)
    report("solve", {"views": len(captured.observations.views)})
    result = solve_captured(captured, o.solve)
    return finish_calibration_tour(captured, result, progress)


def capture_calibration_tour(
    cell: CellConfig,
    tour: CalibrationTour,
    client: ControllerClient,
    camera: CameraBackend,
    options: CalibrateCellOptions | None = None,
    progress: Progress | None = None,
    source: str = "calibration tour",
) -> CapturedTour:
    """The first half of :func:`run_calibration_tour`: the tour driven, the target detected, the
    warming checked, the observations gathered (its refusals)."""
    o = options or CalibrateCellOptions()
    report = progress or (lambda event, data: None)
    t0 = time.perf_counter()
    spec = check_calibration_tour(cell, tour, source)
    captures = TourCapture(tour.tour, client, camera, spec, o.capture, report).run()
    warming = tour_warming([v.temperatures_c for v in captures.views],
                           [v.time_s for v in captures.views])  # fmt: skip
    warn = check_warming(warming, o.max_warming_K, source)  # refuses past the limit
    if warming is not None:
        report("warming", {"line": warning_or(warn, warming)})
    cameras = Cameras.from_stereo(camera.stereo)
    dropped: list[DroppedView] = []
    obs = observations_of(captures, spec, cameras, source, o.capture.strict, dropped)
    for d in dropped:
        report("dropped", {"warning": d.warning(source, len(obs.views))})
    dh = cell.build_robot().dh
    stereo_source = str(cell.calibration_path() or camera.stereo.source)
    prov = cell_provenance(cell, dh, stereo_source, camera.stereo.to_dict())
    return CapturedTour(captures, warming, obs, tuple(dropped), dh, prov, source, t0)


def solve_captured(captured: CapturedTour, options: SolveOptions) -> CalibrationResult:
    """The adjustment of a captured tour (picklable in and out: it may run in a worker
    process; the captures themselves are not needed)."""
    return solve_observations(captured.observations, captured.dh, options,
                              captured.provenance, captured.dropped, captured.source)  # fmt: skip


def solve_observations(
    obs: CalibrationObservations, dh: DHTable, options: SolveOptions, provenance: Provenance,
    dropped: tuple[DroppedView, ...], source: str,
) -> CalibrationResult:  # fmt: skip
    """:func:`solve_calibration` of ``obs``, the ``dropped`` views' refusal rules applied."""
    return solve_without(list(dropped), source, solve_calibration, obs, dh, options, provenance)


def finish_calibration_tour(
    captured: CapturedTour, result: CalibrationResult, progress: Progress | None = None
) -> CellCalibrationRun:
    """The second half of :func:`run_calibration_tour`: the solved calibration with the tour's
    warming noted, and the run's record."""
    if captured.warming is not None:  # kept with the calibration
        cal = replace(result.calibration,
                      notes=(*result.calibration.notes, captured.warming.line()))  # fmt: skip
        result = replace(result, calibration=cal)
    if progress is not None:
        progress("done", {"total_s": result.timings["total_s"]})
    return CellCalibrationRun(captured.captures, captured.observations, result,
                              time.perf_counter() - captured.t0, captured.dropped,
                              captured.warming)  # fmt: skip


def warning_or(warn: str, warming: TourWarming) -> str:
    """The warning when there is one, else the plain report line."""
    return warn or warming.line()


def calibrate_cell(
    cell: CellConfig,
    tour: CalibrationTour,
    client: ControllerClient,
    camera: CameraBackend,
    options: CalibrateCellOptions | None = None,
    progress: Progress | None = None,
) -> CellCalibration:
    """Run the calibration tour on the controller and the camera and return the calibration
    (:func:`run_calibration_tour`, which also gives the captures and timings)."""
    return run_calibration_tour(cell, tour, client, camera, options, progress).calibration
