"""``holecell demo [--out DIR]``: the whole job on the built-in cell, simulated cell and head."""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from cell.commands.argtypes import part_temperature_c
from cell.commands.run_progress import RunBars, bar
from cell.demo.demo import DemoOptions, DemoResult, run_demo
from cell.errors import CellError
from cell.uncertainty.decision import DECISION_RULES, DEFAULT_RULE


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``demo``."""
    p = sub.add_parser(
        "demo",
        help="plan and run the built-in motorcycle frame on the simulated cell",
        description=(
            "Plans the tour of the built-in motorcycle frame, runs it on the simulated "
            "controller over a pseudo-terminal with a warming arm (reference targets measured "
            "during the warm-up, thermal model identified), measures every hole with the "
            "simulated stereo head, and writes DIR/results.sqlite, report.json, report.csv, "
            "run.rrd and report.html (the inspection protocol). The simulated cell has the "
            "errors a real one has, drawn from --seed (D-H geometry, head mount, robot base, "
            "part and plate placement, arm repeatability, stereo calibration, part "
            "temperature; --truth: written down; --ideal: none); the cell is calibrated "
            "first (DIR/cellcal.json; --no-calibration: nominal kinematics) and the run "
            "uses that calibration. Prints the calibration's figures and a summary with the "
            "measurement error against the simulation's truth (in the datum frame and the "
            "fixture frame) and how often the truth lies within U."
        ),
    )
    p.add_argument("--out", default=None, help="run directory (default: out/demo-<time>)")
    p.add_argument("--seed", type=int, default=0, help="seed of the simulated part and noise")
    p.add_argument(
        "--decision",
        choices=DECISION_RULES,
        default=DEFAULT_RULE,
        help="decision rule per hole (default iso14253: ISO 14253-1 with U)",
    )
    p.add_argument(
        "--part-temperature",
        type=part_temperature_c,
        default=None,
        metavar="C",
        help="the simulated part's true temperature (default: the truth file's, else 23 "
        "degC; the run is given a thermometer reading of it)",
    )
    world = p.add_mutually_exclusive_group()
    world.add_argument(
        "--ideal",
        action="store_true",
        help="a perfect simulated arm and head (no geometric error, no repeatability "
        "scatter, the head exactly as calibrated): only image noise and thermal drift",
    )
    world.add_argument(
        "--truth",
        metavar="TRUTH.yaml",
        default=None,
        help="every hidden error of the simulated cell (docs/calibration.md, 'the simulated "
        "truth'; fields left out are drawn from its seed, else --seed; write one with "
        "holecell truth draw)",
    )
    p.add_argument(
        "--no-calibration",
        action="store_true",
        help="do not calibrate the cell first: the run uses the nominal kinematics, base and "
        "head mount (the same truth: shows what the calibration removes)",
    )
    p.add_argument("--calibration-views", type=int, default=120, metavar="N",
                   help="views of the plate in the calibration (default 120, as "
                        "holecell plan-calibration)")  # fmt: skip
    p.add_argument(
        "--calibration-method",
        choices=("images", "projected"),
        default="images",
        help="images (default): drive the calibration tour on the simulated cell, render and "
        "detect the plate in both cameras, as holecell calibrate cell does (about a minute for "
        "120 views); projected: the plate's corners projected through the simulated cell at "
        "the calibration planner's views (seconds, no detector)",
    )
    p.add_argument(
        "--no-referencing",
        action="store_true",
        help="do not survey the reference markers: carry every hole into the part by the arm "
        "(default: survey the markers after the calibration, DIR/markers.json, and locate every "
        "stop against them; docs/referencing.md)",
    )
    p.add_argument("--operator", default="", help="name for the report's operator field")
    p.add_argument("--no-record", action="store_true", help="do not write run.rrd")
    p.add_argument(
        "--no-images",
        action="store_true",
        help="do not keep each stop's stereo pair in DIR/images (about 190 MB)",
    )
    p.add_argument("--spawn", action="store_true", help="also stream to a new Rerun viewer")
    p.add_argument("--connect", metavar="URL", help="also stream to this Rerun viewer (gRPC)")
    p.add_argument("--quiet", action="store_true", help="no progress display")
    p.set_defaults(handler=run_demo_cmd)


def _plan_bars(quiet: bool):
    if quiet:
        return None
    from cell.commands.plan_cmd import StageBars

    return StageBars()


def _recorder_factory(args: argparse.Namespace):
    if args.no_record:
        return None
    from cell.review.recording import Recorder

    def factory(run_dir: Path, cell, tour):
        return Recorder.create(run_dir / "run.rrd", cell, tour, args.spawn, args.connect)

    return factory


def format_calibration(res: DemoResult) -> str:
    """The calibration's figures (mm, deg, um for people)."""
    c = res.calibration
    if c is None:
        return "cell calibration: none (nominal kinematics, base and head mount)"
    cal = c.calibration
    rms = ", ".join(f"{k} {v:.3f} px" for k, v in cal.residual_rms_px.items())
    rows = [
        ("cell calibration", f"{c.method}: {c.seconds:.1f} s"),
        *([("  calibration tour", c.tour_note)] if c.tour_note else []),
        ("  hand-eye error vs truth", f"{c.hand_eye_error_m * 1e3:.4f} mm, "
                                      f"{np.degrees(c.hand_eye_error_rad):.4f} deg (sigma "
                                      f"{c.hand_eye_sigma_m * 1e3:.4f} mm, "
                                      f"{np.degrees(c.hand_eye_sigma_rad):.4f} deg)"),
        ("  reprojection RMS", rms),
        ("  D-H terms", f"{sum(t.free for t in cal.dh_terms)} estimated, "
                        f"{len(c.fixed_terms)} fixed ({', '.join(c.fixed_terms)})"),
        ("  file", str(c.path)),
    ]  # fmt: skip
    width = max(len(k) for k, _ in rows)
    return "\n".join(f"{k:<{width}}  {v}" for k, v in rows)


def format_survey(res: DemoResult) -> str:
    """The survey's figures and how many stops were referenced."""
    v = res.survey
    if v is None:
        return "referencing: none (every hole carried into the part by the arm)"
    r = v.result
    refs = [h.extra.get("referencing", {}) for h in res.run.stored]
    n_ref = sum(1 for x in refs if x.get("referenced"))
    flagged = sum(1 for x in refs if (x.get("arm_registered_m") or 0.0) > 1e-3)
    rows = [
        ("marker survey", f"{len(r.marker_ids)} markers from {r.n_views} views, "
                          f"{r.rms_px:.3f} px RMS, {v.planned_robot_time_s:.0f} s robot time "
                          f"planned ({v.robot_time_s:.0f} s on the simulator's clock, which "
                          f"runs while each pair renders), {v.seconds:.1f} s"),
        ("  vs true markers", f"{v.rms_m * 1e6:.1f} um RMS (max {v.worst_m * 1e6:.1f} um) after "
                              f"a rigid fit; scale sigma {r.scale_sigma_ppm:.1f} ppm"),
        ("  stops referenced", f"{n_ref}/{len(refs)} located against the markers"
                               + (f"; {flagged} off the registered arm by > 1 mm"
                                  if flagged else "")),
        ("  file", str(v.path)),
        *((("  survey tour", v.plan_cache),) if v.plan_cache else ()),
    ]  # fmt: skip
    width = max(len(k) for k, _ in rows)
    return "\n".join(f"{k:<{width}}  {v}" for k, v in rows)


def format_demo(res: DemoResult) -> str:
    """The summary table (mm and um for people)."""
    s, t, tr, dt = res.summary, res.timings, res.truth, res.datum
    measured, planned = s["holes_measured"], s["holes_planned"]
    worst = s["worst_position_m"]
    rows = [
        ("holes measured", f"{bar(measured, planned, 20)} {measured}/{planned}"),
        ("missing / unmeasurable", f"{s['holes_missing']} / {s['holes_unmeasured']}"),
        ("run-time flags", f"{s['holes_failed']} out of tol. / {s['holes_suspect']} suspect "
                           "(a drawing's tolerances are decided in the report, below)"),
        ("decisions (ISO 14253-1)" if s.get("decision_rule") != "simple" else "decisions (simple)",
         f"{s['holes_conforming']} conformance proven / {s['holes_inconclusive']} inconclusive "
         f"/ {s['holes_nonconforming']} nonconformance proven"),
        ("largest U (k=2)", f"position ⌀{s['max_U_position_m'] * 1e6:.1f} µm, diameter "
                            f"{s['max_U_diameter_m'] * 1e6:.1f} µm" if s["max_U_position_m"]
                            else "-"),
        ("part temperature", _part(s.get("part"))),
        ("worst position", f"⌀{worst * 1e3:.4f} mm (ISO 1101; hole {s['worst_hole']}, "
                           f"{s['worst_position_frame']} frame)" if worst else "-"),
        ("cycle time (planned)", f"{res.tour.cycle_time_s:.1f} s"),
        ("  hole tour", str(res.tour.settings.get("plan_cache", "")) or "-"),
        ("position error vs truth", _datum(dt)),
        ("  best fit", _best_fit(dt)),
        ("  in the fixture frame", f"{tr.rms_in_plane_m * 1e6:.1f} um RMS in the hole plane "
                                   f"(max {tr.max_in_plane_m * 1e6:.1f} um; holds the base's and "
                                   "the part's placement)"),
        ("  3-D, fixture frame", f"{tr.rms_m * 1e6:.1f} um RMS (max {tr.max_m * 1e6:.1f} um; "
                                 "along the axis: depth); without thermal compensation "
                                 f"{tr.rms_uncompensated_m * 1e6:.1f} um RMS"),
        ("diameter error, RMS", f"{tr.diameter_rms_m * 1e6:.1f} um"),
        ("truth within U (k=2)", _datum_cov(dt)),
        ("  in the fixture frame", f"{tr.n_covered}/{tr.n_characteristics} "
                                   f"({100 * tr.coverage:.1f} %) of positions and diameters"),
        ("thermal update", res.run.thermal or "-"),
        ("link", f"{res.run.link.get('requests', 0)} requests, "
                 f"{res.run.link.get('retransmits', 0)} retransmitted"),
        ("wall time", f"{t['total_s']:.1f} s (plan {t['plan_s']:.1f} s, calibration "
                      f"{t.get('calibration_s', 0.0):.1f} s, survey "
                      f"{t.get('survey_s', 0.0):.1f} s, run {t['run_s']:.1f} s)"),
        ("run directory", str(res.run_dir)),
    ]  # fmt: skip
    width = max(len(k) for k, _ in rows)
    return "\n".join(f"{k:<{width}}  {v}" for k, v in rows)


def _datum(dt) -> str:
    if dt is None or not dt.n:
        return "-"
    return (f"{dt.rms_in_plane_m * 1e6:.1f} um RMS in the hole plane (max "
            f"{dt.max_in_plane_m * 1e6:.1f} um), datum frame {dt.alignment}")  # fmt: skip


def _best_fit(dt) -> str:
    if dt is None or not dt.n:
        return "-"
    return (f"{dt.best_fit_rms_in_plane_m * 1e6:.1f} um RMS (max "
            f"{dt.best_fit_max_in_plane_m * 1e6:.1f} um), all holes fitted")  # fmt: skip


def _datum_cov(dt) -> str:
    if dt is None or not (dt.position_covered or dt.diameter_covered):
        return "-"
    p, d = dt.position_covered, dt.diameter_covered
    return (f"{sum(p)}/{len(p)} positions ({100 * np.mean(p):.1f} %), {sum(d)}/{len(d)} "
            f"diameters ({100 * np.mean(d):.1f} %), datum frame")  # fmt: skip


def _part(part: dict | None) -> str:
    if not part:
        return "-"
    return (
        f"{part['temperature_c']:.2f} degC +- {part['u_temperature_K']:.2f} K "
        f"({part['source']}); results at 20 degC"
    )


def run_demo_cmd(args: argparse.Namespace) -> int:
    """Handler of ``holecell demo``."""
    out = Path(args.out) if args.out else Path("out") / time.strftime("demo-%Y%m%d-%H%M%S")
    truth = None
    if args.truth is not None:
        from cell.config import load_builtin_cell
        from cell.sim.truth import CellTruth

        truth = CellTruth.load(args.truth, load_builtin_cell(), seed=args.seed)
    if args.calibration_views < 3:
        raise CellError(f"--calibration-views {args.calibration_views}: at least 3 are needed")
    bars = None if args.quiet else RunBars(0)
    res = run_demo(
        out,
        DemoOptions(
            seed=args.seed,
            decision_rule=args.decision,
            part_temperature_c=args.part_temperature,
            realistic=not args.ideal,
            operator=args.operator,
            truth=truth,
            calibrate=not args.no_calibration,
            calibration_views=args.calibration_views,
            calibration_method=args.calibration_method,
            referencing=not args.no_referencing,
            keep_images=not args.no_images,
        ),
        _plan_bars(args.quiet),
        _progress(bars),
        _recorder_factory(args),
    )
    print(format_calibration(res))
    print(format_survey(res))
    print(format_demo(res))
    if not args.no_record:
        print(f"open the recording:  rerun {out / 'run.rrd'}")
    return 0


def _progress(bars: RunBars | None):
    if bars is None:
        return None

    def progress(event: str, data: dict) -> None:
        if event == "state" and data["state"] == "waiting":
            bars.total, bars.done = data["holes"], data["stored"]
        bars(event, data)

    return progress
