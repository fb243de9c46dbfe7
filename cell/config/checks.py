"""Checks of a parsed cell file that need more than its schema: duplicate ids, files and folders
that must exist, meshes that must load, and a robot whose home pose is within its limits and free
of collision. Each returns ``(field path, value, message)`` problems, the form of
:class:`cell.errors.ConfigError`."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from cell.config.target import read_corners
from robots import LimitsError, RobotModelError
from robots.errors import MeshFileError

if TYPE_CHECKING:
    from cell.config.schema import CellConfig

Problem = tuple[str, object, str]


def cell_problems(cfg: CellConfig) -> list[Problem]:
    """Every problem of ``cfg``; the robot is built only once the cheaper checks pass."""
    return (
        duplicate_ids(cfg) + part_temperature_problems(cfg) + path_problems(cfg)
        or mesh_problems(cfg)
        or robot_problems(cfg)
    )


def duplicate_ids(cfg: CellConfig) -> list[Problem]:
    problems = []
    for group, items in (
        ("part.holes", cfg.part.holes),
        ("reference_targets", cfg.reference_targets),
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
