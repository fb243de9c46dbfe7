"""Datums and tolerances in the cell file (docs/gdt.md).

``part.datums`` lists datum features by label; a datum reference frame (DRF) is a list of
labels in precedence (``[A, B, C]``). A datum feature is one of:

- ``plane: {holes: [...]}``: the least-squares plane through the measured centres of the
  listed holes (each centre lies on the surface around its hole: the hole's rim), >= 3 holes;
- ``hole: ID``: the hole's centre (and, as a secondary datum, its axis where it meets the
  primary plane);
- ``pattern: [ID, ...]``: a set of holes located together (least-squares, >= 2 holes);
- ``rps: [{hole: ID, axes: [x, y]}, ...]``: reference point system points, each locking the
  listed axes of the part frame at its hole's nominal (6 locked axes in all).

Frames a DRF may be built from (the primary constrains three degrees of freedom, the
secondary two, the tertiary one): ``plane | hole | hole``, ``plane | pattern`` (the pattern
constrains the remaining three), ``pattern`` (a 3D pattern alone, six) or ``rps`` alone.

Per hole, under ``tolerances`` (a hole's ``position`` is its nominal centre already):
``position: {zone_diameter_m, datums: [A, B, C], material_condition: RFS|MMC|LMC}``
and ``size: {upper_m, lower_m}`` (deviations from the nominal diameter, m, as the drawing
writes them: H8 on 10 mm is ``{upper_m: 2.2e-5, lower_m: 0}``). The older single
``tolerance`` keeps working (see docs/gdt.md); a hole carries either it or ``tolerances``,
never both. Figures too large to be metres (millimetres typed unchanged) are refused by
:mod:`cell.config.plausible`.

``part.alignment`` picks the run's alignment (the frame of the placement and of holes
without a position tolerance): ``{datums: [A, B, C]}`` or
``{best_fit: {holes: [...], method: least_squares|minimax}}``; by default the DRF of the
datums in the order listed.
"""

from __future__ import annotations

from typing import Annotated, Any, Literal

from pydantic import BaseModel, ConfigDict, Field

Problem = tuple[str, object, str]
MATERIAL_CONDITIONS = ("RFS", "MMC", "LMC")
DATUM_KINDS = ("plane", "hole", "pattern", "rps")
#: datum kinds in precedence that make a complete DRF
COMPLETE_FRAMES = (("plane", "hole", "hole"), ("plane", "pattern"), ("pattern",), ("rps",))
AXES = ("x", "y", "z")


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)


class PositionTolerance(_Strict):
    """A position tolerance: a cylindrical zone of diameter ``zone_diameter_m`` (m) about the
    nominal axis, located by the DRF ``datums`` (labels in precedence)."""

    zone_diameter_m: float
    datums: list[str] = []
    material_condition: Literal["RFS", "MMC", "LMC"] = "RFS"
    #: the drawing's name of this tolerance (an AP242 PMI's, ``holecell import-step``)
    pmi_id: str | None = None


class SizeTolerance(_Strict):
    """Limits of a hole's diameter as deviations from its nominal (m): ``lower_m <= upper_m``."""

    upper_m: float
    lower_m: float
    #: the drawing's name of this tolerance (an AP242 PMI's, ``holecell import-step``)
    pmi_id: str | None = None


class Tolerances(_Strict):
    """A hole's drawing tolerances: ``position`` and ``size`` (either may be absent)."""

    position: PositionTolerance | None = None
    size: SizeTolerance | None = None


class DatumPlane(_Strict):
    holes: list[str]


class RpsPoint(_Strict):
    hole: str
    axes: Annotated[list[Literal["x", "y", "z"]], Field(min_length=1, max_length=3)]


class Datum(_Strict):
    """One datum feature: exactly one of ``plane``, ``hole``, ``pattern``, ``rps``."""

    label: Annotated[str, Field(min_length=1)]
    plane: DatumPlane | None = None
    hole: str | None = None
    pattern: list[str] | None = None
    rps: list[RpsPoint] | None = None
    #: the drawing's name of this datum (an AP242 PMI's, ``holecell import-step``)
    pmi_id: str | None = None

    def model_post_init(self, __context: Any) -> None:
        kinds = [k for k in DATUM_KINDS if getattr(self, k) is not None]
        if len(kinds) != 1:
            raise ValueError(f"a datum needs exactly one of {', '.join(DATUM_KINDS)} (got {kinds})")

    @property
    def kind(self) -> str:
        """``plane``, ``hole``, ``pattern`` or ``rps``."""
        return next(k for k in DATUM_KINDS if getattr(self, k) is not None)

    def hole_ids(self) -> list[str]:
        """The holes whose measurements make this datum feature."""
        if self.plane is not None:
            return list(self.plane.holes)
        if self.hole is not None:
            return [self.hole]
        if self.pattern is not None:
            return list(self.pattern)
        return [p.hole for p in self.rps or []]


class BestFit(_Strict):
    """A best-fit alignment over ``holes`` (empty: every measured hole)."""

    holes: list[str] = []
    method: Literal["least_squares", "minimax"] = "least_squares"


class Alignment(_Strict):
    """The run's alignment: a DRF (``datums``) or a best fit (``best_fit``), exactly one."""

    datums: list[str] | None = None
    best_fit: BestFit | None = None

    def model_post_init(self, __context: Any) -> None:
        if (self.datums is None) == (self.best_fit is None):
            raise ValueError("an alignment needs exactly one of datums or best_fit")


def frame_problem(kinds: tuple[str, ...]) -> str | None:
    """Why datum kinds in this precedence make no complete DRF (None: they do)."""
    if kinds in COMPLETE_FRAMES:
        return None
    known = ", ".join(" | ".join(f) for f in COMPLETE_FRAMES)
    return f"datums of kinds {' | '.join(kinds) or '(none)'} make no complete frame ({known})"


def without_drawing(data: dict[str, Any], tolerance_m: float | None = None) -> dict[str, Any]:
    """A cell file's mapping without its datums, alignment and holes' ``tolerances`` (for a
    subset of the built-in frame's holes, whose datum features it may have left out); each
    hole then carries the old single ``tolerance_m`` (None: no tolerance). In place; returned."""
    part = data.get("part", {})
    part.pop("datums", None)
    part.pop("alignment", None)
    for h in part.get("holes", []):
        if h.pop("tolerances", None) is not None and tolerance_m is not None:
            h["tolerance"] = tolerance_m
    return data
