"""Offline inputs of the cell calibration: images (:mod:`.images`), the pose CSV
(:mod:`.posecsv`), intrinsics (:mod:`.intrinsics`) and the worked example set
(:mod:`.example_set`)."""

from __future__ import annotations

from cell.calibration.inputs.example_set import write_example_set
from cell.calibration.inputs.images import observations_from_images
from cell.calibration.inputs.intrinsics import read_intrinsics
from cell.calibration.inputs.posecsv import read_pose_csv

__all__ = ["observations_from_images", "read_intrinsics", "read_pose_csv", "write_example_set"]
