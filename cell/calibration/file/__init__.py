"""The cell calibration file ``cellcal.json``: reading and writing (:mod:`.modelfile`) and
its provenance (:mod:`.provenance`: which cell, robot, tool and head it belongs to)."""

from __future__ import annotations

from cell.calibration.file.modelfile import (
    calibration_to_dict,
    check_age,
    check_belongs,
    fingerprint,
    load_calibration,
    save_calibration,
)
from cell.calibration.file.provenance import cell_provenance

__all__ = [
    "calibration_to_dict",
    "cell_provenance",
    "check_age",
    "check_belongs",
    "fingerprint",
    "load_calibration",
    "save_calibration",
]
