"""Sizes of a hole's drawing figures a cell file may state: beyond, a unit mistake.

A cell file is in metres; a drawing is in millimetres, and a figure copied from it unchanged
(``zone_diameter_m: 0.5`` for a 0.5 mm zone) is 1000 times too large yet valid as a number.
Each figure over its bound below is refused naming the field, with the unit hint. The bounds
sit far above any real tolerance of a hole a stereo head measures (a general tolerance of
+-1 mm, ISO 2768 coarse, on a hole up to a few hundred mm) and far below the millimetre figure
of the tightest one typed as metres (2 um, IT3 on a small hole, reads as 2 mm).
"""

from __future__ import annotations

from typing import Any

Problem = tuple[str, object, str]

#: largest position zone diameter (m) of a hole
MAX_ZONE_DIAMETER_M = 0.01
#: largest size deviation (m, either limit, from the nominal diameter)
MAX_SIZE_DEVIATION_M = 0.002
#: largest old single ``tolerance`` (m): a zone of twice it
MAX_TOLERANCE_M = MAX_ZONE_DIAMETER_M / 2
#: largest hole diameter (m): a hole the head sees whole in one image
MAX_DIAMETER_M = 0.5

HINT = "lengths are in metres, this looks like millimetres"


def _over(field: str, value: float, bound_m: float, what: str) -> list[Problem]:
    if abs(value) <= bound_m:
        return []
    return [(field, value, f"{what} over {bound_m * 1e3:g} mm: {HINT}")]


def size_problems(where: str, hole: Any) -> list[Problem]:
    """The figures of the hole at field path ``where`` too large to be metres."""
    out = _over(f"{where}.diameter", hole.diameter, MAX_DIAMETER_M, "a hole diameter")
    if hole.tolerance is not None:
        out += _over(f"{where}.tolerance", hole.tolerance, MAX_TOLERANCE_M, "a tolerance")
    tol = hole.tolerances
    if tol is None:
        return out
    if tol.position is not None:
        field = f"{where}.tolerances.position.zone_diameter_m"
        out += _over(field, tol.position.zone_diameter_m, MAX_ZONE_DIAMETER_M, "a position zone")
    if tol.size is not None:
        for name in ("upper_m", "lower_m"):
            value = getattr(tol.size, name)
            field = f"{where}.tolerances.size.{name}"
            out += _over(field, value, MAX_SIZE_DEVIATION_M, "a size deviation")
    return out


#: the largest coordinate (m) of anything in a robot cell, or of a hole in its part: a cell is a
#: few metres across, so a figure beyond was typed in millimetres
MAX_CELL_COORDINATE_M = 20.0
#: the largest offset (m) of the head from the flange, and of its stand-off
MAX_TOOL_OFFSET_M = 2.0


def length_problems(cfg: Any) -> list[Problem]:
    """Positions and offsets of the cell file (``cfg``: a :class:`CellConfig`) too large to be
    metres: poses of the robot, the part and the calibration target, holes, reference targets
    and markers beyond :data:`MAX_CELL_COORDINATE_M`; the tool's offset and stand-off beyond
    :data:`MAX_TOOL_OFFSET_M`."""
    out: list[Problem] = []

    def coords(field: str, xyz: Any, bound: float, what: str) -> None:
        worst = max(abs(float(v)) for v in xyz)
        if worst > bound:
            out.append((field, list(xyz), f"{what} over {bound:g} m: {HINT}"))

    coords("robot.base.xyz", cfg.robot.base.xyz, MAX_CELL_COORDINATE_M, "a coordinate")
    coords("part.base.xyz", cfg.part.base.xyz, MAX_CELL_COORDINATE_M, "a coordinate")
    coords("tool.tool0_to_tcp.xyz", cfg.tool.tool0_to_tcp.xyz, MAX_TOOL_OFFSET_M, "an offset")
    if cfg.tool.standoff_m > MAX_TOOL_OFFSET_M:
        out.append(("tool.standoff_m", cfg.tool.standoff_m,
                    f"a stand-off over {MAX_TOOL_OFFSET_M:g} m: {HINT}"))  # fmt: skip
    for group in ("part.holes", "reference_targets", "reference_markers"):
        items = cfg.part.holes if group == "part.holes" else getattr(cfg, group)
        for i, item in enumerate(items):
            coords(f"{group}[{i}].position", item.position, MAX_CELL_COORDINATE_M, "a coordinate")
    if cfg.calibration_target is not None:
        xyz = cfg.calibration_target.pose.xyz
        coords("calibration_target.pose.xyz", xyz, MAX_CELL_COORDINATE_M, "a coordinate")
    return out
