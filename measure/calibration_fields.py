"""Reading a number field of a calibration file (``stereo.json``): present and numeric, or a
:class:`~measure.errors.CalibrationError` naming the file and the field."""

from __future__ import annotations

from typing import Any

import numpy as np

from measure.errors import CalibrationError


def number_field(data: dict[str, Any], key: str, source: str, name: str) -> np.ndarray:
    """``data[key]`` as a float64 array (any shape; the caller checks it); ``name`` is the
    field's path in the file ``source`` for the error."""
    if key not in data:
        raise CalibrationError(source, name, "missing")
    try:
        return np.asarray(data[key], dtype=np.float64)
    except (TypeError, ValueError):
        raise CalibrationError(source, name, f"must be numbers, got {data[key]!r}") from None
