"""``holecell run``: run a tour on the cell controller, measure every hole, store and report."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable
from pathlib import Path

from cell.calibration.use import (
    MAX_AGE_DAYS,
    RunCalibration,
    RunGeometry,
    load_run_calibration,
    store_calibration,
    stored_calibration_path,
)
from cell.camera import cell_stereo
from cell.camera.open import check_camera_url, open_camera
from cell.commands.argtypes import (
    non_negative_float,
    non_negative_int,
    part_temperature_c,
    positive_float,
    temperature_u_K,
)
from cell.commands.controller_check import connect_checked
from cell.commands.controller_cmd import (
    add_rws_arguments,
    add_rws_trigger_argument,
    trigger_pulse,
    watched_client,
)
from cell.commands.run_progress import RunBars
from cell.config import CellConfig, load_cell
from cell.config.tours import check_tour
from cell.errors import CellError
from cell.link import messages as m
from cell.link.client import ControllerClient
from cell.referencing.markersfile import MARKERS_FILENAME
from cell.referencing.markersfile import MAX_AGE_DAYS as MARKERS_MAX_AGE_DAYS
from cell.referencing.network import load_network
from cell.review.recording import Recorder
from cell.review.report import format_summary, write_report
from cell.run.reference import plan_reference_tour
from cell.run.runner import Runner, RunOptions
from cell.run.setup import RunFiles, check_new_run_dir, resume_run, start_run
from cell.run.thermal_check import check_model_for_cell, check_model_sensors
from cell.uncertainty.decision import DECISION_RULES, DEFAULT_RULE
from planner import load_tour
from robots.files import write_text_atomic
from robots.thermal.model import ThermalModel
from robots.thermal.modelfile import load_model


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``run``."""
    p = sub.add_parser(
        "run",
        help="run a tour on the controller and measure every hole",
        description=(
            "Reads TOUR (tour.json from holecell plan) and CELL (the cell file it was planned "
            "for; refused otherwise), connects to the controller at --port (/dev/ttyS0, "
            "socket://host:port or a pty path) and the stereo head at --camera, measures the "
            "reference targets in --reference-rounds rounds and identifies the thermal "
            "compensation from them (when the readings changed between rounds; else it keeps "
            "the --thermal model, checked against the cell, or the nominal kinematics), then "
            "measures every hole. "
            "Writes RUN_DIR/results.sqlite (every hole in its own transaction), report.json "
            "and report.csv, and records the run to RUN_DIR/run.rrd (Rerun; --spawn or --connect "
            "to watch it live), and report.html, the inspection protocol (U per hole, ISO 14253-1 "
            "decision, plots). --resume RUN_DIR continues a stopped run from the first hole not "
            "stored, with the cell and tour stored in it."
        ),
    )
    p.add_argument("tour", nargs="?", help="tour.json (not with --resume)")
    p.add_argument("--cell", help="cell file the tour was planned for")
    p.add_argument("--port", required=True, help="controller port URL")
    p.add_argument("--camera", required=True,
                   help="stereo head: tcp://HOST:PORT (the simulator) or "
                        "gige://IP_LEFT,IP_RIGHT[?trigger=...] (GigE Vision, "
                        "docs/real_cell.md)")  # fmt: skip
    p.add_argument("--out", default=None, help="run directory to create (default: runs/<tour>)")
    p.add_argument("--resume", metavar="RUN_DIR", help="continue the run stored in RUN_DIR")
    p.add_argument("--thermal", help="thermal.json model to start from (holecell thermal)")
    p.add_argument("--calibration", metavar="CELLCAL.json",
                   help="the cell calibration (holecell calibrate cell): holes are carried "
                        "through its D-H table and hand-eye, each stop's joints are corrected "
                        "for it, the thermal model identifies on top of it and its covariance "
                        "joins every hole's budget. Refused if made for another robot, tool, "
                        "cell or stereo calibration, or older than --calibration-max-age. "
                        "Copied into the run directory; --resume uses that copy")  # fmt: skip
    p.add_argument(
        "--calibration-max-age",
        type=non_negative_float,
        default=MAX_AGE_DAYS,
        metavar="DAYS",
        help=f"refuse a calibration older than this (default {MAX_AGE_DAYS:g} days)",
    )
    p.add_argument(
        "--markers",
        metavar="MARKERS.json",
        help="the surveyed reference markers (holecell survey): every stop is located "
        "against the markers it sees and the hole carried into the part by that "
        "pose, not by the arm (a stop with fewer than 4 markers falls back to "
        "the arm, flagged). Refused when surveyed for another cell or head, or "
        "older than --markers-max-age",
    )
    p.add_argument(
        "--markers-max-age",
        type=positive_float,
        default=MARKERS_MAX_AGE_DAYS,
        metavar="DAYS",
        help=f"refuse a survey older than this (default {MARKERS_MAX_AGE_DAYS:g} days)",
    )
    p.add_argument("--reference-rounds", type=non_negative_int, default=2,
                   help="rounds over the reference targets before the holes, "
                        "--reference-interval-s apart (default 2: a model is identified only "
                        "from rounds at different temperatures; 0: no thermal update, the "
                        "--thermal model or the nominal kinematics)")  # fmt: skip
    p.add_argument("--reference-interval-s", type=non_negative_float, default=300.0,
                   help="controller seconds between reference rounds")  # fmt: skip
    p.add_argument("--settle-s", type=non_negative_float, default=0.2,
                   help="settling wait (s)")  # fmt: skip
    p.add_argument("--part-temperature", type=part_temperature_c, metavar="C",
                   help="the part's temperature (degC, read on the part): every position and "
                        "diameter is reported at 20 degC (ISO 1). Without it: the cell file's "
                        "part.temperature_c, else 20 degC assumed with 2.9 K uncertainty; a "
                        "resumed run keeps the one it stored")  # fmt: skip
    p.add_argument(
        "--u-part-temperature",
        type=temperature_u_K,
        metavar="K",
        help="standard uncertainty of --part-temperature (default 0.2 K)",
    )
    p.add_argument(
        "--decision",
        choices=DECISION_RULES,
        default=DEFAULT_RULE,
        help="decision rule per hole: iso14253 (ISO 14253-1: conformance or "
        "nonconformance proven with the expanded uncertainty U, else "
        "inconclusive; default) or simple (deviation against tolerance)",
    )
    p.add_argument("--operator", default="", help="name for the report's operator field")
    p.add_argument("--spawn", action="store_true", help="also stream to a new Rerun viewer")
    p.add_argument("--connect", metavar="URL", help="also stream to this Rerun viewer (gRPC)")
    p.add_argument("--no-record", action="store_true", help="do not write run.rrd")
    p.add_argument(
        "--no-images",
        action="store_true",
        help="do not keep each stop's stereo pair in RUN_DIR/images (lossless PNG, "
        "for audit and holecell remeasure; 4.7 MB a stop on the simulated 5 MP head)",
    )
    p.add_argument(
        "--reset",
        action="store_true",
        help="clear a latched e-stop or fault of the controller (RESET) before the "
        "run, after the operator confirms the cell is safe (at once with --yes)",
    )
    p.add_argument("--yes", action="store_true", help="start (and --reset) without asking")
    p.add_argument("--quiet", action="store_true", help="no progress display")
    add_rws_arguments(p, prefix="rws-")  # --rws: watch the controller's state (RWS 1.0)
    add_rws_trigger_argument(p)
    p.set_defaults(handler=run_run)


def _thermal_model(
    path: str | None, cell: CellConfig, calibration: RunCalibration | None
) -> ThermalModel | None:
    """The ``--thermal`` model, refused unless it was identified for this cell's arm, D-H table
    (the calibrated one with ``--calibration``), base pose and tool (the sensor count is
    checked against the controller once connected)."""
    if not path:
        return None
    model = load_model(path)
    arm = cell.build_arm()
    check_model_for_cell(model, RunGeometry(arm, cell_stereo(cell), calibration),
                         cell.robot.model, path)  # fmt: skip
    return model


def _calibration(
    args: argparse.Namespace, cell: CellConfig, run_dir: Path | None
) -> RunCalibration | None:
    """``--calibration`` checked for ``cell`` (robot, tool, cell, stereo, age), or the copy a
    resumed run (``run_dir``) stored, checked against its stored cell (not its age)."""
    if run_dir is not None:
        if args.calibration:
            raise CellError("--resume uses the calibration stored with the run; do not give "
                            "--calibration")  # fmt: skip
        stored = stored_calibration_path(run_dir)
        if stored is None:
            return None
        return load_run_calibration(stored, cell, cell.build_robot(), cell_stereo(cell), None)
    if not args.calibration:
        return None
    return load_run_calibration(args.calibration, cell, cell.build_robot(), cell_stereo(cell),
                                args.calibration_max_age)  # fmt: skip


def _markers(args: argparse.Namespace, cell: CellConfig, run_dir: Path | None):
    """``--markers`` checked for ``cell`` (layout, head, age), or the copy a resumed run
    stored (not its age); None: not referenced."""
    if run_dir is not None:
        if args.markers:
            raise CellError("--resume uses the markers stored with the run; do not give --markers")
        stored = run_dir / MARKERS_FILENAME
        return load_network(stored, cell, cell_stereo(cell), None) if stored.exists() else None
    if not args.markers:
        return None
    return load_network(args.markers, cell, cell_stereo(cell), args.markers_max_age)


def _prepare(
    args: argparse.Namespace,
) -> tuple[CellConfig, ThermalModel | None, RunCalibration | None, Callable[[], RunFiles]]:
    """The cell, the checked thermal model and calibration, and how to open the run's store
    once controller and head answer. Every input is checked here, before anything is planned,
    connected or written."""
    if args.resume:
        if args.tour or args.cell:
            raise CellError("--resume takes the cell and tour from the run; give neither")
        files = resume_run(args.resume)  # checked now, reopened once the cell answers
        files.store.close()
        cal = _calibration(args, files.cell, Path(args.resume))
        args.network = _markers(args, files.cell, Path(args.resume))
        model = _thermal_model(args.thermal, files.cell, cal)
        return files.cell, model, cal, lambda: resume_run(args.resume)
    if not args.tour or not args.cell:
        raise CellError("give TOUR and --cell CELL (or --resume RUN_DIR)")
    out = Path(args.out) if args.out else Path("runs") / Path(args.tour).stem
    check_new_run_dir(out)
    cell = load_cell(args.cell)
    tour = load_tour(args.tour)
    check_tour(tour, cell, args.tour)
    cal = _calibration(args, cell, None)
    args.network = _markers(args, cell, None)
    model = _thermal_model(args.thermal, cell, cal)
    reference = (
        plan_reference_tour(cell, tour=tour)
        if cell.reference_targets and args.reference_rounds
        else None
    )
    return cell, model, cal, lambda: start_run(out, cell, tour, args.tour, args.port, reference)


def _rrd_path(run_dir: Path) -> Path:
    """``run.rrd``; a resumed run records to ``run.resumed-N.rrd`` next to it."""
    path, n = run_dir / "run.rrd", 1
    while path.exists():
        path, n = run_dir / f"run.resumed-{n}.rrd", n + 1
    return path


def _clear_fault(client: ControllerClient, args: argparse.Namespace) -> None:
    """Refuse to start on a latched e-stop or fault unless ``--reset`` (confirmed) clears it."""
    st = client.status()
    if st.state not in (m.State.ESTOP, m.State.FAULT):
        return
    what = f"controller at {args.port} is in {st.state.name} ({st.fault.name})"
    if not args.reset:
        raise CellError(f"{what}: clear the cause at the cell, then run again with --reset")
    if not args.yes and sys.stdin.isatty():
        answer = input(f"{what}. Is the cell safe to move? Type 'reset' to send RESET: ")
        if answer.strip() != "reset":
            raise CellError(f"{what}: RESET not confirmed; nothing was sent")
    client.reset()
    st = client.status()
    if st.state in (m.State.ESTOP, m.State.FAULT):
        raise CellError(f"{what} after RESET: release the emergency stop at the cell first")
    print(f"controller fault cleared ({what} before RESET)", file=sys.stderr)


def _report_stopped_run(run_dir: Path, operator: str = "") -> None:
    """Write the report of a run that stopped early and print its summary on stderr (a store
    that cannot be read any more is said so, not raised over the reason the run stopped)."""
    try:
        print(format_summary(write_report(run_dir, operator)), file=sys.stderr)
    except (CellError, OSError) as exc:
        print(f"no report written: {exc}", file=sys.stderr)


def _ask_start() -> None:
    input("press Enter to start the run (Ctrl-C to cancel) ")


def run_run(args: argparse.Namespace) -> int:
    """Handler of ``holecell run``."""
    check_camera_url(args.camera)
    cell, model, calibration, open_files = _prepare(args)
    client = watched_client(ControllerClient(args.port), args)
    camera = recorder = files = None
    try:
        connect_checked(client, args.port, cell.robot.model)
        _clear_fault(client, args)
        if model is not None:
            check_model_sensors(model, len(client.status().temperatures_c), args.thermal)
        camera = open_camera(args.camera, cell_stereo(cell), trigger_pulse(client, args))
        files = open_files()
        run_dir = files.store.path.parent
        if calibration is not None:
            store_calibration(calibration, run_dir)
        if args.network is not None and args.markers:
            write_text_atomic(run_dir / MARKERS_FILENAME,
                              Path(args.markers).read_text(encoding="utf-8"))  # fmt: skip
        stored = len(files.store.done_ids())
        options = RunOptions(
            settle_s=args.settle_s,
            reference_rounds=args.reference_rounds,
            reference_interval_s=args.reference_interval_s,
            part_temperature_c=args.part_temperature,
            u_part_temperature_K=args.u_part_temperature,
            decision_rule=args.decision,
            keep_images=not args.no_images,
        )
        progress = None if args.quiet else RunBars(len(files.tour.stops), stored)
        if not args.no_record:
            recorder = Recorder.create(_rrd_path(run_dir), files.cell, files.tour, args.spawn,
                                       args.connect)  # fmt: skip
        runner = Runner(files.cell, files.tour, files.store, client, camera, options,
                        files.reference, model, progress, recorder, calibration,
                        markers=args.network)  # fmt: skip
        try:
            result = runner.run(None if args.yes or not sys.stdin.isatty() else _ask_start)
        except BaseException:
            files.store.close()
            _report_stopped_run(run_dir, args.operator)
            raise
        if result.thermal:
            print(result.thermal)
    finally:
        client.close()
        if camera is not None:
            camera.close()
        if recorder is not None:
            recorder.close()
        if files is not None:
            files.store.close()
    print(format_summary(write_report(run_dir, args.operator)))
    print(f"run directory: {run_dir}")
    return 0
