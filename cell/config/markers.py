"""Reference markers and scale bars in the cell file (photogrammetric referencing).

``reference_markers``: circular coded targets, a white dot on black, surveyed once by bundle
adjustment (``holecell survey``) so that every stop can be located against them. A marker's
``position`` is in the part frame when it is stuck on the part (``on: part``: it moves with the
part's placement) and in the cell frame when it is on the fixture or the table
(``on: fixture``). ``normal`` is the unit normal out of the marker's face, ``diameter_m`` the
white dot's diameter, ``code`` the number its code ring (or tag) carries (default: the marker's
place in the list, 0 for the first), which the detector reads to identify it.

``scale_bars``: two markers a calibrated length apart (``length_m``, with its expanded
uncertainty ``U_m``, k = 2): the survey's scale.
"""

from __future__ import annotations

from typing import Annotated, Any, Literal

import numpy as np
from pydantic import Field, field_validator, model_validator

from cell.config.pose import Positive, Vec3, _Strict, unit_normal

#: the largest marker dot a cell may hold (m): a larger one is most likely written in mm
MAX_MARKER_DIAMETER_M = 0.05


class ReferenceMarker(_Strict):
    id: Annotated[str, Field(min_length=1)]
    position: Vec3
    normal: Vec3
    diameter_m: Annotated[float, Field(gt=0, le=MAX_MARKER_DIAMETER_M)]
    on: Literal["part", "fixture"]
    code: Annotated[int, Field(ge=0)] | None = None

    _unit_normal = field_validator("normal")(lambda cls, v: unit_normal(v))

    @model_validator(mode="before")
    @classmethod
    def _yaml_on(cls, data: Any) -> Any:
        """YAML 1.1 (PyYAML) reads the key ``on`` as the boolean True: take it back."""
        if isinstance(data, dict) and True in data and "on" not in data:
            data = {("on" if k is True else k): v for k, v in data.items()}
        return data


class ScaleBar(_Strict):
    from_: str = Field(alias="from", min_length=1)
    to: Annotated[str, Field(min_length=1)]
    length_m: Positive
    U_m: Annotated[float, Field(ge=0)]


def marker_in_cell(
    marker: ReferenceMarker, T_cell_part: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Nominal centre (m) and unit normal of ``marker`` in the cell frame."""
    p, n = np.asarray(marker.position, float), np.asarray(marker.normal, float)
    if marker.on == "part":
        return T_cell_part[:3, :3] @ p + T_cell_part[:3, 3], T_cell_part[:3, :3] @ n
    return p, n


def marker_codes(markers: list[ReferenceMarker]) -> dict[int, str]:
    """The code each marker carries (its ``code``, else its place in the list) -> its id."""
    return {(i if m.code is None else m.code): m.id for i, m in enumerate(markers)}
