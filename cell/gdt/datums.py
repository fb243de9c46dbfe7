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
:mod:`cell.gdt.plausible`.

``part.alignment`` picks the run's alignment (the frame of the placement and of holes
without a position tolerance): ``{datums: [A, B, C]}`` or
``{best_fit: {holes: [...], method: least_squares|minimax}}``; by default the DRF of the
datums in the order listed.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Annotated, Any, Literal

from pydantic import BaseModel, ConfigDict, Field

from cell.gdt.plausible import size_problems

if TYPE_CHECKING:
    from cell.config import CellConfig

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


class SizeTolerance(_Strict):
    """Limits of a hole's diameter as deviations from its nominal (m): ``lower_m <= upper_m``."""

    upper_m: float
    lower_m: float


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


def gdt_problems(cfg: CellConfig) -> list[Problem]:
    """Every problem of the datums and tolerances of ``cfg`` (field path, value, message)."""
    holes = {h.id for h in cfg.part.holes}
    datums = {d.label: d for d in cfg.part.datums}
    problems: list[Problem] = []
    seen: set[str] = set()
    for i, d in enumerate(cfg.part.datums):
        where = f"part.datums[{i}]"
        if d.label in seen:
            problems.append((f"{where}.label", d.label, "duplicate datum label"))
        seen.add(d.label)
        problems += _datum_problems(where, d, holes)
    for i, h in enumerate(cfg.part.holes):
        problems += size_problems(f"part.holes[{i}]", h) + _hole_problems(
            f"part.holes[{i}]", h, datums
        )
    a = cfg.part.alignment
    if a is not None and a.datums is not None:
        problems += _frame_problems("part.alignment.datums", a.datums, datums)
    if a is not None and a.best_fit is not None:
        for j, hid in enumerate(a.best_fit.holes):
            if hid not in holes:
                problems.append((f"part.alignment.best_fit.holes[{j}]", hid, "no such hole"))
        if 0 < len(a.best_fit.holes) < 3:
            problems.append(("part.alignment.best_fit.holes", a.best_fit.holes,
                             "a best fit needs at least 3 holes"))  # fmt: skip
    return problems


def _datum_problems(where: str, d: Datum, holes: set[str]) -> list[Problem]:
    out: list[Problem] = []
    sub = {"plane": ".plane.holes", "hole": ".hole", "pattern": ".pattern", "rps": ".rps"}[d.kind]
    for j, hid in enumerate(d.hole_ids()):
        if hid not in holes:
            field = f"{where}{sub}" if d.kind == "hole" else f"{where}{sub}[{j}]"
            out.append((field + (".hole" if d.kind == "rps" else ""), hid,
                        f"datum {d.label} names no hole of part.holes"))  # fmt: skip
    need = {"plane": 3, "pattern": 2, "hole": 1, "rps": 3}[d.kind]
    if len(set(d.hole_ids())) < need:
        out.append((f"{where}{sub}", d.hole_ids(), f"a {d.kind} datum needs at least {need} holes"))
    if d.rps is not None:
        locked = sum(len(set(p.axes)) for p in d.rps)
        if locked != 6:
            out.append((f"{where}.rps", locked, "RPS points must lock 6 axes in all"))
    return out


def _hole_problems(where: str, h: Any, datums: dict[str, Datum]) -> list[Problem]:
    out: list[Problem] = []
    tol = h.tolerances
    if tol is None:
        return out
    if h.tolerance is not None:
        out.append(
            (
                f"{where}.tolerance",
                h.tolerance,
                "give either tolerance (the old single figure) or tolerances, not both",
            )
        )
    where = f"{where}.tolerances"
    p = tol.position
    if p is not None:
        if p.zone_diameter_m < 0:
            out.append((f"{where}.position.zone_diameter_m", p.zone_diameter_m,
                        "a position zone cannot be negative"))  # fmt: skip
        if p.zone_diameter_m == 0 and p.material_condition == "RFS":
            out.append(
                (
                    f"{where}.position.zone_diameter_m",
                    0.0,
                    "a zero zone needs MMC or LMC (zero positional tolerance)",
                )
            )
        if p.material_condition != "RFS" and tol.size is None:
            out.append(
                (
                    f"{where}.position.material_condition",
                    p.material_condition,
                    "MMC and LMC need the hole's size limits (tolerances.size)",
                )
            )
        if not p.datums:
            out.append((f"{where}.position.datums", [], "a position tolerance needs datums"))
        else:
            out += _frame_problems(f"{where}.position.datums", p.datums, datums)
    s = tol.size
    if s is not None and s.upper_m < s.lower_m:
        out.append(
            (
                f"{where}.size",
                {"upper_m": s.upper_m, "lower_m": s.lower_m},
                "limits in the wrong order: upper_m must not be below lower_m",
            )
        )
    if s is not None and h.diameter + s.lower_m <= 0:
        out.append((f"{where}.size.lower_m", s.lower_m, "the lower limit leaves no hole"))
    return out


def _frame_problems(where: str, labels: list[str], datums: dict[str, Datum]) -> list[Problem]:
    out: list[Problem] = []
    for j, lab in enumerate(labels):
        if lab not in datums:
            out.append((f"{where}[{j}]", lab, "no such datum in part.datums"))
    if len(set(labels)) != len(labels):
        out.append((where, labels, "a datum is named twice"))
    if out:
        return out
    why = frame_problem(tuple(datums[lab].kind for lab in labels))
    return [(where, labels, why)] if why else []
