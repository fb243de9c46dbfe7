"""Photogrammetric referencing: reference markers surveyed once by bundle adjustment, then
every stop located against them, so the arm only carries the head (docs/referencing.md).

- :mod:`.observations`: the markers' centres a view saw, in both images;
- :mod:`.visibility`, :mod:`.layout`: which markers a view sees; a layout for a cell;
- :mod:`.survey`: plan, refusals, the adjustment (GTSAM, SciPy as the reference), the gauge;
- :mod:`.markersfile`: ``markers.json``;
- :mod:`.resection`: one stop located against the surveyed markers;
- :mod:`.synthetic`: observations with a known truth.
"""

from __future__ import annotations

from cell.referencing.errors import MarkersFileError, ReferencingError, SurveyRefusedError
from cell.referencing.markersfile import check_markers, load_markers, save_markers
from cell.referencing.observations import MarkerView
from cell.referencing.resection import Resection, resect
from cell.referencing.survey.result import SurveyResult
from cell.referencing.survey.survey import SurveyOptions, survey

__all__ = [
    "MarkerView",
    "MarkersFileError",
    "ReferencingError",
    "Resection",
    "SurveyOptions",
    "SurveyRefusedError",
    "SurveyResult",
    "check_markers",
    "load_markers",
    "resect",
    "save_markers",
    "survey",
]
