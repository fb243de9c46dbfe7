"""The stereo calibration of a cell's head."""

from __future__ import annotations

from cell.config import CellConfig
from measure import StereoCalibration
from measure.synth import standard_stereo


def cell_stereo(cell: CellConfig) -> StereoCalibration:
    """The cell's stereo calibration file, or the standard head (:func:`measure.synth.
    standard_stereo`, the simulated head) when the cell names none."""
    path = cell.calibration_path()
    return StereoCalibration.load(path) if path is not None else standard_stereo()
