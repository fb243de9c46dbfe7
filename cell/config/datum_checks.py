"""The checks of a cell file's datums and tolerances (docs/gdt.md) that need the whole cell:
hole ids a datum names, datum labels a frame names, complete frames, tolerance limits.

Each problem is ``(field path, value, message)``, the form of :class:`cell.errors.ConfigError`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from cell.config.datums import Datum, Problem, frame_problem
from cell.config.plausible import size_problems

if TYPE_CHECKING:
    from cell.config.schema import CellConfig


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
