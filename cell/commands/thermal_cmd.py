"""``holecell thermal``: identify the thermal error model, and predict compensated TCP positions.

    holecell thermal identify OBS.csv --cell CELL -o thermal.json
    holecell thermal predict thermal.json POSES.csv [-o OUT.csv] [--command]
    holecell thermal simulate --cell CELL -o OBS.csv   (warm-up observations of a simulated arm)
    holecell thermal plan-views --cell CELL [--tour tour.json] -o views.csv   (thermal_plan_cmd)

The CSV formats are described in :mod:`robots.thermal.csvio` and docs/thermal.md.
"""

from __future__ import annotations

import argparse
import csv
import io
import sys
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from cell.commands.argtypes import output_file
from cell.commands.group_help import help_handler
from robots.dh import DHTable
from robots.dh_models import dh_table
from robots.files import write_text_atomic
from robots.models import MODELS
from robots.thermal import (
    CellGeometry,
    DriftTruth,
    IdentificationResult,
    IdentifyOptions,
    ThermalSpec,
    command,
    default_settings,
    identify,
    reference_from_cold,
    simulate_observations,
)
from robots.thermal.compensate import compensated_T_cell_tcp
from robots.thermal.csvio import read_observations, read_poses, write_observations
from robots.thermal.errors import ThermalDataError
from robots.thermal.modelfile import load_model, save_model

if TYPE_CHECKING:
    from cell.config import CellConfig

PREDICT_COLUMNS = (
    "tcp_x_cell_m",
    "tcp_y_cell_m",
    "tcp_z_cell_m",
    "drift_x_m",
    "drift_y_m",
    "drift_z_m",
    "drift_m",
)


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add ``thermal identify`` and ``thermal predict``."""
    p = subparsers.add_parser(
        "thermal",
        help="temperature error compensation: identify the model, predict compensated poses",
        description="Temperature error compensation on the D-H model of the arm.",
    )
    sub = p.add_subparsers(dest="thermal_command", metavar="STEP")
    p.set_defaults(handler=help_handler(p))
    ident = sub.add_parser(
        "identify",
        help="fit the thermal model to reference-target observations",
        description="Reads OBS.csv (time_s, target_id, q1_rad..q6_rad, temp_<sensor>_degC, "
        "x_tcp_m, y_tcp_m, z_tcp_m) and the cell file (reference targets, base and tool "
        "poses); prints the coefficients, their uncertainty, the refused terms and the fit "
        "residual; writes the model (thermal.json).",
    )
    ident.add_argument("observations", type=Path, metavar="OBS.csv")
    ident.add_argument("--cell", required=True, help="cell file (YAML) or built-in cell name")
    ident.add_argument("-o", "--output", type=output_file, required=True, metavar="thermal.json")
    ident.add_argument(
        "--sensor-map",
        metavar="S1,..,S6",
        help="sensor driving each of the six links (default: one sensor drives all; six in order)",
    )
    ident.add_argument("--offsets", action="store_true", help="also fit joint-offset drift terms")
    ident.add_argument(
        "--max-condition",
        type=float,
        default=IdentifyOptions().max_condition,
        help="refuse terms until the normalised Jacobian's condition number is below this "
        "(default %(default)g)",
    )
    ident.set_defaults(handler=run_identify)
    pred = sub.add_parser(
        "predict",
        help="compensated TCP positions for joint vectors and temperatures",
        description="Reads thermal.json and POSES.csv (q1_rad..q6_rad and a temp_<sensor>_degC "
        "column per model sensor; other columns are passed through); writes the compensated "
        "TCP position in the cell frame and its drift from the nominal (m), as CSV.",
    )
    pred.add_argument("model", type=Path, metavar="thermal.json")
    pred.add_argument("poses", type=Path, metavar="POSES.csv")
    pred.add_argument(
        "-o", "--output", type=output_file, help="output CSV (default: standard output)"
    )
    pred.add_argument(
        "--command",
        dest="joint_command",
        action="store_true",
        help="also give the joint vector that puts the warm TCP on its nominal pose "
        "(q*_cmd_rad, command_status); exit code 1 if any does not converge",
    )
    pred.set_defaults(handler=run_predict)
    sim = sub.add_parser(
        "simulate",
        help="observations of the cell's reference targets on a simulated warming arm",
        description="Observes the reference views designed for the cell (or --views), "
        "simulates the reference warm-up (robots.thermal.default_settings: about "
        "+15 K in two hours) and writes the observations CSV that 'thermal identify' reads.",
    )
    sim.add_argument("--cell", required=True, help="cell file (YAML) or built-in cell name")
    sim.add_argument("-o", "--output", type=output_file, required=True, metavar="OBS.csv")
    sim.add_argument("--hours", type=float, default=2.0, help="warm-up duration (default 2)")
    sim.add_argument("--every-s", type=float, default=300.0, help="period (s, default 300)")
    sim.add_argument("--noise-um", type=float, default=5.0, help="noise per axis (um, default 5)")
    sim.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    sim.add_argument(
        "--views",
        type=Path,
        metavar="views.csv",
        help="reference views to observe (from 'thermal plan-views'; default: the plan designed "
        "for the cell's holes, as holecell run uses without a tour)",
    )
    sim.set_defaults(handler=run_simulate)
    from cell.commands import thermal_plan_cmd

    thermal_plan_cmd.register(sub)


def _table_of(cfg: CellConfig) -> DHTable:
    """The D-H table of the cell's arm (a URDF path is relative to the cell file's folder)."""
    if cfg.robot.model in MODELS:
        return dh_table(cfg.robot.model)
    return cfg.build_robot().dh


def _geometry(cfg: CellConfig, cell_arg: str) -> tuple[CellGeometry, str, DHTable]:
    from cell.errors import ConfigError

    if not cfg.reference_targets:
        raise ConfigError(
            str(cfg.source_path or cell_arg),
            [("reference_targets", [], "the cell has no reference targets to identify from")],
        )
    targets = {t.id: np.asarray(t.position, float) for t in cfg.reference_targets}
    geometry = CellGeometry(cfg.T_cell_base(), cfg.T_tool0_tcp(), targets)
    return geometry, cfg.robot.model, _table_of(cfg)


def _print_result(res: IdentificationResult, source: Path) -> None:
    m, rep = res.model, res.report
    sensors = ", ".join(m.spec.sensor_names)
    print(
        f"thermal model from {source}: {res.n_rows} rows in {res.n_groups} pose groups, "
        f"sensors {sensors}"
    )
    print(
        f"rank {rep.rank} of {len(rep.candidates)} candidate terms; condition "
        f"{rep.condition_kept:.3g} for the {len(rep.kept)} kept (all with an effect: "
        f"{rep.condition_all:.3g})"
    )
    print(f"{'term':<10} {'value':>12} {'1-sigma':>12}  unit")
    for name, value in m.coefficients.items():
        unit = "1/K" if name.startswith("k_") else "rad/K"
        print(f"{name:<10} {value:>12.4e} {m.std[name]:>12.2e}  {unit}")
    for name, reason in rep.refused.items():
        print(f"refused {name}: {reason}")
    print(
        f"fit residual RMS {res.residual_rms_m * 1e6:.2f} um (without the model "
        f"{res.residual_rms_before_m * 1e6:.2f} um), noise estimate {res.sigma_m * 1e6:.2f} um, "
        f"{res.timings['identify_s']:.3f} s"
    )


def run_identify(args: argparse.Namespace) -> int:
    """Identify the model from the observations and write thermal.json."""
    from cell.config import load_cell

    geometry, model_name, table = _geometry(load_cell(args.cell), args.cell)
    obs = read_observations(args.observations, known_targets=set(geometry.targets_cell_m))
    link_sensors = None
    if args.sensor_map:
        link_sensors = tuple(s.strip() for s in args.sensor_map.split(","))
    spec = ThermalSpec.mapped(
        obs.sensor_names, reference_from_cold(obs), link_sensors, offsets=args.offsets
    )
    options = IdentifyOptions(max_condition=args.max_condition)
    res = identify(obs, geometry, table, spec, options, robot_model=model_name)
    _print_result(res, args.observations)
    save_model(args.output, res.model)
    print(f"wrote {args.output}")
    return 0


def _check_joint_limits(path: Path, robot_model: str, q_rad: np.ndarray) -> None:
    """Refuse joint vectors outside the limits of the model's arm, naming the line and column."""
    spec = MODELS.get(robot_model)
    if spec is None:
        return
    lower, upper = spec.limits()
    outside = np.argwhere((q_rad < lower - 1e-9) | (q_rad > upper + 1e-9))
    if len(outside):
        row, joint = (int(v) for v in outside[0])
        raise ThermalDataError(
            str(path),
            f"q{joint + 1}_rad = {q_rad[row, joint]:.6g} is outside the {spec.title} limits "
            f"[{lower[joint]:.4g}, {upper[joint]:.4g}] rad",
            line=row + 2,
            column=f"q{joint + 1}_rad",
        )


def run_predict(args: argparse.Namespace) -> int:
    """Compensated TCP positions (and optionally commands) for every row of POSES.csv."""
    model = load_model(args.model)
    names = model.spec.sensor_names
    used = tuple(dict.fromkeys(names[i] for i in model.spec.sensor_of_link))
    poses = read_poses(args.poses, names, used)
    _check_joint_limits(args.poses, model.robot_model, poses.q_rad)
    # the model file's own base and tool: predict needs no cell file
    T_cell_tcp = compensated_T_cell_tcp(
        model, model.T_cell_base, model.T_tool0_tcp, poses.q_rad, poses.temps_degC
    )
    cold = np.broadcast_to(model.spec.reference_degC, poses.temps_degC.shape)
    nominal = compensated_T_cell_tcp(model, model.T_cell_base, model.T_tool0_tcp, poses.q_rad, cold)
    p = T_cell_tcp[:, :3, 3]
    drift = p - nominal[:, :3, 3]
    header = list(poses.header) + list(PREDICT_COLUMNS)
    cmds = []
    if args.joint_command:
        header += [f"q{i}_cmd_rad" for i in range(1, 7)] + ["command_status"]
        cmds = [command(model, q, T) for q, T in zip(poses.q_rad, poses.temps_degC, strict=True)]
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(header)
    for i, row in enumerate(poses.rows):
        values = [*p[i], *drift[i], np.linalg.norm(drift[i])]
        extra = [repr(float(v)) for v in values]
        if cmds:
            extra += [repr(float(v)) for v in cmds[i].q_rad] + [cmds[i].status]
        w.writerow(list(row) + extra)
    if args.output:
        write_text_atomic(args.output, buf.getvalue())
        print(f"wrote {len(poses.rows)} rows to {args.output}", file=sys.stderr)
    else:
        sys.stdout.write(buf.getvalue())
    return 0 if all(c.ok for c in cmds) else 1


def run_simulate(args: argparse.Namespace) -> int:
    """Simulated warm-up observations of the cell's reference targets."""
    from cell.config import load_cell
    from cell.errors import CellError

    if not (0 < args.hours < 1e3 and 0 < args.every_s < 1e6 and 0 <= args.noise_um < 1e6):
        raise CellError(
            f"--hours {args.hours:g}, --every-s {args.every_s:g}, --noise-um {args.noise_um:g}: "
            "need a positive duration and period and a non-negative noise"
        )
    cfg = load_cell(args.cell)
    geometry, _, table = _geometry(cfg, args.cell)
    if args.views is not None:
        from cell.commands.thermal_plan_cmd import read_views

        poses = read_views(args.views, cfg)
    else:
        from cell.run.reference import design_reference_plan

        poses = design_reference_plan(cfg).poses
    truth = DriftTruth(table, default_settings(), seed=args.seed)
    times = np.arange(0.0, args.hours * 3600.0 + 1e-9, args.every_s)
    obs = simulate_observations(
        truth.T_base_tool0,
        truth.sensor_readings,
        truth.settings.sensor_names,
        geometry,
        poses,
        times,
        noise_m=args.noise_um * 1e-6,
        seed=args.seed,
    )
    write_observations(args.output, obs)
    print(
        f"wrote {len(obs)} observations ({len(poses)} poses x {len(times)} times) to {args.output}"
    )
    return 0
