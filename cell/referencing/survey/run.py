"""The survey in the cell: run the survey tour (:class:`SurveyCapture`), then one adjustment of
every view (:func:`cell.referencing.survey.survey.survey`)."""

from __future__ import annotations

import time
from dataclasses import dataclass

from cell.camera import CameraBackend
from cell.config import CellConfig
from cell.link.client import ControllerClient
from cell.referencing.sigma import SIGMA_FLOOR_PX
from cell.referencing.survey.capture import (
    Progress,
    SurveyCapture,
    SurveyCaptures,
    SurveyCaptureSettings,
)
from cell.referencing.survey.result import SurveyResult
from cell.referencing.survey.survey import SurveyOptions, survey
from cell.referencing.survey.tour import SurveyTour
from measure import StereoCalibration


@dataclass(frozen=True)
class SurveyRunOptions:
    """Wait after "in position" (s), the markers' stated centre noise per image axis (px) and
    the floor of the centre noise the covariances are stated at (px,
    :mod:`cell.referencing.sigma`)."""

    settle_s: float = 0.2
    sigma_px: float = 0.05
    sigma_floor_px: float = SIGMA_FLOOR_PX


@dataclass(frozen=True, eq=False)
class SurveyRun:
    """What :func:`run_survey` did: the tour, the captures, the adjustment and its wall time."""

    tour: SurveyTour
    captures: SurveyCaptures
    result: SurveyResult
    solve_s: float


def run_survey(
    cell: CellConfig,
    planned: SurveyTour,
    client: ControllerClient,
    camera: CameraBackend,
    stereo: StereoCalibration,
    options: SurveyRunOptions | None = None,
    progress: Progress | None = None,
) -> SurveyRun:
    """Run the survey tour and adjust the network; refusals raise
    :class:`cell.referencing.SurveyRefusedError` (nothing is written by this function)."""
    o = options or SurveyRunOptions()
    cap = SurveyCapture(cell, planned, client, camera, stereo,
                        SurveyCaptureSettings(settle_s=o.settle_s), progress).run()  # fmt: skip
    t = time.perf_counter()
    result = survey(
        cell, stereo, cap.views, SurveyOptions(sigma_px=o.sigma_px, sigma_floor_px=o.sigma_floor_px)
    )
    return SurveyRun(planned, cap, result, time.perf_counter() - t)
