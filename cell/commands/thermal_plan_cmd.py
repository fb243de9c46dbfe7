"""``holecell thermal plan-views``: the reference plan designed for the tour.

    holecell thermal plan-views --cell CELL [--tour tour.json] -o views.csv [--views N]
        [--try-target X,Y,Z ...] [--suggest-target] [--hours 2] [--every-s 300] [--noise-um 5]

Chooses the reference views that minimise the thermal model's predicted error at the tour's
stops (:mod:`robots.thermal.design`, the plan ``holecell run`` uses), writes them as CSV
(``view_id, target_id, q1_rad .. q6_rad, tilt_rad, azimuth_rad``) and prints the predicted
residual per stop, the old recommended plan's for comparison, and what a further target at each
``--try-target`` position (or the best places found by ``--suggest-target``) would give.
"""

from __future__ import annotations

import argparse
import csv
import io
import math
from dataclasses import replace
from pathlib import Path

import numpy as np

from cell.commands.argtypes import non_negative_int, output_file, positive_float
from cell.config import CellConfig, ReferenceTarget, load_cell
from cell.config.tours import check_tour, hole_stops
from cell.errors import CellError
from cell.run.reference import design_reference_plan, fixed_reference_plan
from cell.run.target_suggest import suggest_targets
from planner import load_tour
from robots.files import write_text_atomic
from robots.thermal.design import Design, DesignOptions, evaluate
from robots.thermal.errors import ThermalError

VIEW_COLUMNS = ("view_id", "target_id", *(f"q{i}_rad" for i in range(1, 7)), "tilt_rad",
                "azimuth_rad")  # fmt: skip


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``thermal plan-views`` to the ``thermal`` subcommands ``sub``."""
    p = sub.add_parser(
        "plan-views",
        help="design the reference views for the tour (optimal experimental design)",
        description="Chooses the reference-target views (reachable, collision-free) that "
        "minimise the thermal model's predicted TCP error at the tour's stops (without --tour: "
        "at each hole's viewpoint nearest home), writes them (view_id, target_id, "
        "q1_rad..q6_rad, tilt_rad, azimuth_rad) and prints the predicted residual per stop at "
        "the end of the anticipated warm-up. holecell run uses the same plan.",
    )
    p.add_argument("--cell", required=True, help="cell file (YAML) or built-in cell name")
    p.add_argument("--tour", type=Path, metavar="tour.json", help="the tour to design for")
    p.add_argument("-o", "--output", type=output_file, required=True, metavar="views.csv")
    p.add_argument(
        "--views", type=non_negative_int, default=0, metavar="N",
        help="number of views (default: three per reference target)",
    )  # fmt: skip
    p.add_argument(
        "--try-target", action="append", default=[], metavar="X,Y,Z",
        help="a candidate position (cell frame, m, normal up) for a further reference target: "
        "prints the predicted residual with it (repeatable)",
    )  # fmt: skip
    p.add_argument(
        "--suggest-target", action="store_true",
        help="score places for a further target on the top faces of the environment's upright "
        "boxes (0.1 m grid) and print the best three (takes some seconds)",
    )  # fmt: skip
    d = DesignOptions()
    p.add_argument(
        "--hours",
        type=positive_float,
        default=d.duration_s / 3600,
        help="reference warm-up duration (h, default %(default)g)",
    )
    p.add_argument(
        "--every-s",
        type=positive_float,
        default=d.every_s,
        help="period of the reference rounds (s, default %(default)g)",
    )
    p.add_argument("--noise-um", type=positive_float, default=d.noise_m * 1e6,
                   help="stereo noise per axis (um, default %(default)g)")  # fmt: skip
    p.set_defaults(handler=run_plan_views)


def _stops(cell: CellConfig, tour_path: Path | None) -> tuple[list[str], np.ndarray]:
    if tour_path is None:
        return hole_stops(cell)
    tour = load_tour(tour_path)
    check_tour(tour, cell, str(tour_path))
    if not tour.stops:
        raise CellError(f"{tour_path}: stops: the tour has no stops to design the plan for")
    return [s.hole_id for s in tour.stops], np.array([s.q for s in tour.stops], float)


def _target(text: str, k: int) -> ReferenceTarget:
    try:
        xyz = [float(v) for v in text.split(",")]
    except ValueError:
        xyz = []
    if len(xyz) != 3 or not all(math.isfinite(v) for v in xyz):
        raise CellError(f"--try-target {text!r}: expected X,Y,Z in metres (cell frame)")
    return ReferenceTarget(id=f"TRY{k + 1}", position=xyz, normal=[0.0, 0.0, 1.0], diameter=0.01)


def _old_plan_rms(cell: CellConfig, stops: np.ndarray, options: DesignOptions) -> float:
    arm = cell.build_arm()
    q = np.array([qq for _, qq in fixed_reference_plan(cell)])
    sigma, _ = evaluate(arm.dh, cell.T_cell_base(), cell.T_tool0_tcp(), q, stops, options)
    return float(np.sqrt(np.mean(sigma**2)))


def write_views(path: Path, design: Design) -> None:
    """``views.csv`` (atomically: a temporary name renamed into place)."""
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(VIEW_COLUMNS)
    for k, v in enumerate(design.views):
        w.writerow([k, v.target_id, *(repr(float(x)) for x in v.q_rad), repr(v.tilt_rad),
                    repr(v.azimuth_rad)])  # fmt: skip
    write_text_atomic(path, buf.getvalue())


def read_views(path: Path, cell: CellConfig) -> list[tuple[str, np.ndarray]]:
    """``(target id, joints rad)`` per row of a ``views.csv``; a missing column, a non-number,
    an unknown target or joints outside the arm's limits are refused naming line and column."""
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise CellError(f"{path}: not readable ({exc})") from None
    rows = list(csv.DictReader(io.StringIO(text)))
    header = next(csv.reader(io.StringIO(text)), [])
    missing = [c for c in VIEW_COLUMNS[1:8] if c not in header]
    if missing:
        raise CellError(f"{path}: line 1: missing column(s) {', '.join(missing)}")
    if not rows:
        raise CellError(f"{path}: no views")
    known = {t.id for t in cell.reference_targets}
    arm = cell.build_arm()
    out = []
    for line, row in enumerate(rows, start=2):
        if row["target_id"] not in known:
            raise CellError(
                f"{path}: line {line}: target_id: {row['target_id']!r} is not a reference target "
                f"of the cell ({', '.join(sorted(known)) or 'none'})"
            )
        q = []
        for i in range(1, 7):
            col = f"q{i}_rad"
            try:
                q.append(float(row[col]))
            except (TypeError, ValueError):
                q.append(math.nan)
            if not math.isfinite(q[-1]):
                raise CellError(f"{path}: line {line}: {col}: not a finite number ({row[col]!r})")
            if not arm.lower[i - 1] - 1e-9 <= q[-1] <= arm.upper[i - 1] + 1e-9:
                raise CellError(f"{path}: line {line}: {col}: {q[-1]:.6g} is outside the limits")
        out.append((row["target_id"], np.array(q)))
    return out


def run_plan_views(args: argparse.Namespace) -> int:
    """Design the reference views, write them, print the predicted residual per stop."""
    cell = load_cell(args.cell)
    extra = [_target(t, k) for k, t in enumerate(args.try_target)]
    if args.every_s > args.hours * 3600:
        raise CellError(
            f"--every-s {args.every_s:g}: longer than the warm-up (--hours {args.hours:g})"
        )
    names, stops = _stops(cell, args.tour)
    options = DesignOptions(
        n_views=args.views or None, duration_s=args.hours * 3600, every_s=args.every_s,
        noise_m=args.noise_um * 1e-6,
    )  # fmt: skip
    design = design_reference_plan(cell, stops, options)
    write_views(args.output, design)
    rms = design.predicted_rms_m
    print(
        f"reference plan for {len(stops)} stops of {cell.name}: {len(design.views)} views of "
        f"{len({v.target_id for v in design.views})} targets, chosen from "
        f"{design.n_candidates} reachable collision-free candidates"
    )
    for tid, reason in design.skipped.items():
        print(f"target {tid}: no usable view ({reason})")
    print(
        f"predicted residual at the end of a {options.duration_s / 3600:g} h warm-up to "
        f"+{options.rise_K:g} K ({options.noise_m * 1e6:g} um noise, rounds every "
        f"{options.every_s:g} s), 1-sigma 3D:"
    )
    for name, s in zip(names, design.stop_sigma_m, strict=True):
        print(f"  {name:<10} {s * 1e6:7.2f} um")
    print(f"RMS over the stops {rms * 1e6:.2f} um, max {design.stop_sigma_m.max() * 1e6:.2f} um")
    try:
        old = f"RMS {_old_plan_rms(cell, stops, options) * 1e6:.2f} um"
    except ThermalError as exc:
        old = f"not possible ({exc})"
    print(f"old recommended plan (3 fixed views per target): {old}")
    n_more = len(design.views) + 3
    for t in extra:
        with_t = cell.model_copy(update={"reference_targets": [*cell.reference_targets, t]})
        more = design_reference_plan(with_t, stops, replace(options, n_views=n_more))
        same = design_reference_plan(cell, stops, replace(options, n_views=n_more))
        used = sum(v.target_id == t.id for v in more.views)
        print(
            f"with a target at {t.position}: {n_more} views ({used} of it) RMS "
            f"{more.predicted_rms_m * 1e6:.2f} um; {n_more} views of the present targets "
            f"{same.predicted_rms_m * 1e6:.2f} um"
        )
    if args.suggest_target:
        baseline, scores = suggest_targets(cell, stops, options)
        print(
            f"a further target, {len(scores)} places on environment boxes scored: "
            f"{len(design.views) + 3} views of the present targets give {baseline * 1e6:.2f} um"
        )
        for sc in scores[:3]:
            x, y, z = sc.position_m
            print(f"  at ({x:.3f}, {y:.3f}, {z:.3f}) m: {sc.predicted_rms_m * 1e6:.2f} um "
                  f"({sc.views_of_it} views of it)")  # fmt: skip
    print(f"wrote {len(design.views)} views to {args.output}")
    return 0
