"""Checks of a parsed cell file that need more than its schema: duplicate ids, files and folders
that must exist, meshes that must load, and a robot whose home pose is within its limits and free
of collision. Each returns ``(field path, value, message)`` problems, the form of
:class:`cell.errors.ConfigError`."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from cell.config.markers import marker_in_cell
from cell.config.plausible import length_problems
from cell.config.target import read_corners
from robots import LimitsError, RobotModelError
from robots.errors import MeshFileError

if TYPE_CHECKING:
    from cell.config.schema import CellConfig

Problem = tuple[str, object, str]


def cell_problems(cfg: CellConfig) -> list[Problem]:
    """Every problem of ``cfg``; the robot is built only once the cheaper checks pass."""
    return (
        duplicate_ids(cfg)
        + length_problems(cfg)
        + marker_problems(cfg)
        + part_temperature_problems(cfg)
        + path_problems(cfg)
        or mesh_problems(cfg)
        or robot_problems(cfg)
    )


#: a scale bar's length may differ from its markers' nominal distance by at most this (m)
SCALE_BAR_NOMINAL_TOL_M = 0.005


def marker_problems(cfg: CellConfig) -> list[Problem]:
    """Scale bars that name unknown markers, join a marker to itself, or whose length does not
    match their markers' nominal distance (a wrong id or a length in mm)."""
    problems: list[Problem] = []
    markers = {m.id: m for m in cfg.reference_markers}
    T_cell_part = cfg.T_cell_part()
    for i, bar in enumerate(cfg.scale_bars):
        ends = []
        for key, mid in (("from", bar.from_), ("to", bar.to)):
            if mid not in markers:
                problems.append((f"scale_bars[{i}].{key}", mid, "names no reference marker"))
            else:
                ends.append(marker_in_cell(markers[mid], T_cell_part)[0])
        if bar.from_ == bar.to:
            problems.append((f"scale_bars[{i}].to", bar.to, "a scale bar joins two markers"))
        elif len(ends) == 2:
            nominal = float(np.linalg.norm(ends[1] - ends[0]))
            if abs(nominal - bar.length_m) > SCALE_BAR_NOMINAL_TOL_M:
                problems.append((f"scale_bars[{i}].length_m", bar.length_m,
                                 f"its markers are {nominal:.4f} m apart nominally"))  # fmt: skip
    return problems


def duplicate_ids(cfg: CellConfig) -> list[Problem]:
    problems = []
    codes: set[int] = set()
    for i, m in enumerate(cfg.reference_markers):
        code = i if m.code is None else m.code
        if code in codes:
            problems.append((f"reference_markers[{i}].code", code, "duplicate code (the code "
                             "is the marker's place in the list when not given)"))  # fmt: skip
        codes.add(code)
    for group, items in (
        ("part.holes", cfg.part.holes),
        ("reference_targets", cfg.reference_targets),
        ("reference_markers", cfg.reference_markers),
    ):
        seen: set[str] = set()
        for i, item in enumerate(items):
            if item.id in seen:
                problems.append((f"{group}[{i}].id", item.id, "duplicate id"))
            seen.add(item.id)
    return problems


def part_temperature_problems(cfg: CellConfig) -> list[Problem]:
    if cfg.part.u_temperature_K is not None and cfg.part.temperature_c is None:
        msg = "needs part.temperature_c (the temperature it is the uncertainty of)"
        return [("part.u_temperature_K", cfg.part.u_temperature_K, msg)]
    return []


def path_problems(cfg: CellConfig) -> list[Problem]:
    """Files and folders the cell names that are not there (resolved against the cell file)."""
    problems: list[Problem] = []
    calibration = cfg.calibration_path()
    if calibration is not None and not calibration.is_file():
        problems.append(("tool.calibration", str(calibration), "no such file"))
    for i, folder in enumerate(cfg.package_paths()):
        if not folder.is_dir():
            problems.append((f"robot.package_paths[{i}]", str(folder), "no such folder"))
    return problems + target_problems(cfg)


def target_problems(cfg: CellConfig) -> list[Problem]:
    """A measured corner file of the calibration target that is missing or wrong."""
    t = cfg.calibration_target
    path = None if t is None else t.corners_path(cfg.base_dir)
    if path is None:
        return []
    _, problems = read_corners(path, t.target_spec().object_points(), t.pitch_m)
    return [("calibration_target.corners_file", str(path), p) for p in problems]


def mesh_problems(cfg: CellConfig) -> list[Problem]:
    problems = []
    for group, shapes in (
        ("tool.shapes", cfg.tool.shapes),
        ("part.obstacles", cfg.part.obstacles),
        ("environment.obstacles", cfg.environment.obstacles),
    ):
        for i, spec in enumerate(shapes):
            if spec.mesh is None:
                continue
            path = spec.mesh.resolved(cfg.base_dir)
            try:
                spec.mesh.load(cfg.base_dir)
            except MeshFileError as exc:
                problems.append((f"{group}[{i}].mesh.path", str(path), exc.reason))
    return problems


def robot_problems(cfg: CellConfig) -> list[Problem]:
    try:
        arm = cfg.build_arm()
    except LimitsError as exc:
        return [("robot.limits.position", cfg.robot.limits.position, str(exc))]
    except RobotModelError as exc:
        return [("robot.model", cfg.robot.model, str(exc))]
    q = cfg.home_q()
    if not np.all(np.isfinite(q)):
        return [("robot.home", cfg.robot.home, "joint values must be finite numbers (rad)")]
    if not arm.within_limits(q):
        bad = [arm.joint_names[i] for i in range(6) if not arm.lower[i] <= q[i] <= arm.upper[i]]
        return [
            (
                "robot.home",
                cfg.robot.home,
                f"outside the joint limits of {arm.name} ({', '.join(bad)})",
            )
        ]
    if arm.in_collision(q):
        pairs = ", ".join(f"{a} / {b}" for a, b in arm.colliding_pairs(q)[:3])
        return [("robot.home", cfg.robot.home, f"in collision ({pairs})")]
    return []
