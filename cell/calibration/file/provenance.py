"""Fingerprints tying a calibration to its robot, tool, cell and stereo calibration.

- robot: the model name and its nominal D-H table;
- tool: the cell file's ``tool`` section (mount, standoff, shapes, stereo file);
- cell: the cell's name and the robot's base pose in it;
- stereo: the content of ``stereo.json`` (or of the mono intrinsics).

A run computes the same fingerprints from its cell file and refuses a ``cellcal.json`` whose
fingerprints differ (:func:`cell.calibration.file.modelfile.check_belongs`).
"""

from __future__ import annotations

from typing import Any

from cell.calibration.estimate.result import Provenance
from cell.calibration.file.modelfile import fingerprint
from cell.config import CellConfig
from robots.dh import DHTable


def robot_fingerprint(model: str, dh: DHTable) -> str:
    """Fingerprint of an arm: model name and nominal D-H table."""
    return fingerprint(
        {"model": model, "dh": [dh.a_m, dh.d_m, dh.alpha_rad, dh.theta_offset_rad, dh.joint_sign]}
    )


def cell_provenance(
    cell: CellConfig | None,
    dh: DHTable | None,
    stereo_source: str | None,
    stereo_content: Any,
) -> Provenance:
    """The provenance of a calibration of ``cell`` (``None``: offline data without a cell)."""
    stereo_fp = fingerprint(stereo_content) if stereo_content is not None else None
    if cell is None:
        return Provenance(stereo_source=stereo_source, stereo_fingerprint=stereo_fp)
    model = cell.robot.model
    return Provenance(
        robot_model=model,
        robot_fingerprint=robot_fingerprint(model, dh) if dh is not None else None,
        tool_fingerprint=fingerprint(cell.tool.model_dump(mode="json")),
        cell_fingerprint=fingerprint(
            {"name": cell.name, "base": cell.robot.base.model_dump(mode="json")}
        ),
        stereo_source=stereo_source,
        stereo_fingerprint=stereo_fp,
    )
