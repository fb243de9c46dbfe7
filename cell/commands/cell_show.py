"""``holecell cell show [CELL]``: summary of a cell file and the reach of every hole."""

from __future__ import annotations

import argparse
import math

import numpy as np

from cell.commands.group_help import help_handler
from cell.config import CellConfig, load_cell
from cell.errors import CellError
from planner.reach import hole_reach
from robots import Arm


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``cell`` with its ``show`` subcommand."""
    cell = sub.add_parser("cell", help="inspect a cell file", description="Inspect a cell file.")
    cell_sub = cell.add_subparsers(dest="cell_command", metavar="ACTION")
    show = cell_sub.add_parser(
        "show",
        help="summarise a cell and the reach of each hole",
        description=(
            "Reads CELL (a cell.yaml; default: the built-in motorcycle frame) and prints the "
            "robot, "
            "tool, part, obstacles and, for each hole, how many IK solutions of its nominal "
            "viewpoint (roll about the view axis sampled) are within limits and collision-free. "
            "Writes nothing."
        ),
    )
    show.add_argument("cell", nargs="?", default=None, help="cell file (default: built-in)")
    show.add_argument("--roll-step-deg", type=float, default=15.0, help="roll sampling (deg)")
    show.set_defaults(handler=run_show)
    cell.set_defaults(handler=help_handler(cell))


def _count(n: int, noun: str) -> str:
    """``n`` and the noun, plural unless ``n`` is 1 (``1 obstacle``, ``3 obstacles``)."""
    return f"{n} {noun}" if n == 1 else f"{n} {noun}s"


def _summary(cfg: CellConfig) -> list[str]:
    arm = cfg.build_arm()
    base = cfg.robot.base
    lines = [
        f"cell      {cfg.name}  ({cfg.source_path})",
        f"robot     {arm.name}  base xyz {base.xyz}  home {np.round(cfg.home_q(), 4).tolist()} rad",
        "          limits  vel " + " ".join(f"{v:.2f}" for v in arm.velocity_limit) + " rad/s",
        *_robot_lines(arm),
        f"tool      tcp {cfg.tool.tool0_to_tcp.xyz} from tool0, standoff {cfg.tool.standoff_m} m, "
        f"{len(cfg.tool.shapes)} shapes",
        f"clearance arm {cfg.robot.clearance_m * 1e3:g} mm, tool {cfg.tool.clearance_m * 1e3:g} mm "
        "(to obstacles; the tool's also to the arm)",
        f"part      base xyz {cfg.part.base.xyz}, {_count(len(cfg.part.holes), 'hole')}"
        + (f" (with {cfg.part.holes_csv})" if cfg.part.holes_csv else "")
        + ", "
        f"{_count(len(cfg.part.obstacles), 'obstacle')}",
        f"cell      {_count(len(cfg.environment.obstacles), 'environment obstacle')}, "
        f"{_count(len(cfg.reference_targets), 'reference target')}",
    ]
    t = cfg.calibration_target
    if t is not None:
        lines.append(f"target    {t.pattern} {t.cols} x {t.rows}, pitch {t.pitch_m * 1e3:g} mm, "
                     f"at xyz {t.pose.xyz} (the plate is an obstacle)")  # fmt: skip
    if arm.collision.excluded_pairs:
        lines.append(
            f"note      bodies touching at q=0, not checked: {arm.collision.excluded_pairs}"
        )
    return lines


def _robot_lines(arm: Arm) -> list[str]:
    """Where the arm came from: URDF, meshes, limits, the derived OPW parameters."""
    k = arm.kinematics
    n_meshes = sum(len(v) for v in arm.loaded.meshes.values())
    lengths = " ".join(f"{name} {v:.4f}" for name, v in arm.opw.lengths().items())
    pos = " ".join(f"[{lo:.3f}, {hi:.3f}]" for lo, hi in zip(arm.lower, arm.upper, strict=True))
    return [
        f"          urdf    {arm.urdf_path}  ({n_meshes} collision meshes)",
        f"          limits  pos {pos} rad",
        f"          OPW     {lengths} m; signs {[int(s) for s in arm.opw.sign]}; "
        f"URDF vs OPW {k.fk_error_m:.1e} m over 128 configurations",
        "          D-H     " + ("derived from the same axes" if k.dh else f"none: {k.dh_problem}"),
    ]


def run_show(args: argparse.Namespace) -> int:
    """Print the summary and the per-hole reach table; exit 1 when a hole is unreachable."""
    cfg = load_cell(args.cell)
    if args.roll_step_deg <= 0 or args.roll_step_deg > 360:
        raise CellError(f"--roll-step-deg must be in (0, 360], got {args.roll_step_deg}")
    print("\n".join(_summary(cfg)))
    arm = cfg.build_arm()
    step = math.radians(args.roll_step_deg)
    print(f"\n{'hole':8s} {'diam mm':>8s} {'IK sols':>8s} {'free':>6s} {'rolls ok':>9s}  note")
    unreachable = 0
    rows = [(h.id, h.diameter_m, h.position_m, h.normal) for h in cfg.holes_in_cell()]
    rows += [
        (f"{t.id}*", t.diameter, np.array(t.position), np.array(t.normal))
        for t in cfg.reference_targets
    ]
    if cfg.calibration_target is not None:  # its centre, viewed along its normal
        t = cfg.calibration_target
        rows.append(("target#", t.pitch_m, *t.centre_and_normal(t.T_cell_target())))
    for hid, diameter, position, normal in rows:
        r = hole_reach(arm, hid, position, normal, cfg.tool.standoff_m, step)
        unreachable += not r.reachable
        note = "" if r.reachable else f"UNREACHABLE: {r.reason}"
        if r.reachable and r.rolls_free < r.n_rolls // 4:
            note = "hard: few rolls usable"
        if r.reachable and r.tilt_deg > 0:
            note = f"tilted: no free view along the axis, free {r.tilt_deg:g} deg off it"
        print(
            f"{hid:8s} {diameter * 1e3:8.1f} {r.n_solutions:8d} {r.n_free:6d} "
            f"{r.rolls_free:4d}/{r.n_rolls:<4d}  {note}"
        )
    legend = "* reference target" + ("; # calibration target's centre (diam: its pitch)"
                                     if cfg.calibration_target is not None else "")  # fmt: skip
    print(f"\n{legend}.  {len(rows) - unreachable} of {len(rows)} reachable.")
    _markers(cfg)
    return 1 if unreachable else 0


def _markers(cfg: CellConfig) -> None:
    """The reference markers each hole's stop sees in both cameras (docs/referencing.md); the
    holes whose stop cannot be located against 4 well-spread markers are named."""
    if not cfg.reference_markers:
        return
    from cell.camera import cell_stereo
    from cell.referencing.layout import markers_seen_per_hole

    seen = markers_seen_per_hole(cfg, cell_stereo(cfg))
    fixture = sum(m.on == "fixture" for m in cfg.reference_markers)
    print(f"\nreference markers: {len(cfg.reference_markers)} ({fixture} on the fixture), "
          f"{_count(len(cfg.scale_bars), 'scale bar')}; seen by each hole's stop in both "
          "cameras (the worse of roll 0 and 90 deg):")  # fmt: skip
    for hid, ids in seen.items():
        print(f"  {hid:8s} {len(ids):2d}  {' '.join(ids)}")
    short = [h for h, ids in seen.items() if len(ids) < 4]
    if short:
        print(
            f"cannot be located against 4 well-spread markers: {', '.join(short)} (these stops "
            "fall back to the arm)"
        )
    else:
        print(f"every hole's stop sees at least 4 well-spread markers ({len(seen)} holes)")
