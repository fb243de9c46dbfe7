"""``holecell import-step PART.step -o holes.csv``: the holes (and PMI, and mesh) of a STEP file."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

import yaml

from cell.commands.argtypes import positive_float


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``import-step``."""
    p = sub.add_parser(
        "import-step",
        help="holes, datums and tolerances from a STEP file (holes CSV, cell-file part)",
        description=(
            "Reads PART.step (AP203, AP214, AP242) with OpenCascade and finds its holes: "
            "internal cylindrical walls all the way round, coaxial walls one hole (a "
            "counterbore: the entry bore is measured, every bore listed), through or blind, "
            "with the entry circle's centre and the outward normal (docs/cad_import.md). "
            "Writes them as a holes CSV (part.holes_csv); --yaml writes the cell file's part "
            "section with the AP242 PMI's datums and tolerances; --mesh the collision mesh."
        ),
    )
    p.add_argument("step", metavar="PART.step", help="the STEP file")
    p.add_argument("-o", "--output", default="holes.csv", help="holes CSV (default holes.csv)")
    p.add_argument(
        "--units", default="mm", choices=("m", "mm", "um"), help="lengths in the CSV (mm)"
    )
    p.add_argument("--yaml", default=None, help="also write the part section (holes, datums)")
    p.add_argument("--mesh", default=None, help="also write the collision mesh (STL, metres)")
    p.add_argument(
        "--deflection-mm",
        type=positive_float,
        default=0.2,
        help="the mesh's largest distance from the surface (mm, default 0.2)",
    )
    p.set_defaults(handler=run_import_step)


def _part_yaml(rows: list[dict[str, Any]], datums: list[dict[str, Any]]) -> str:
    holes = []
    for r in rows:
        h = {k: r[k] for k in ("id", "position", "normal", "diameter")}
        if r.get("tolerances"):
            h["tolerances"] = r["tolerances"]
        holes.append(h)
    part: dict[str, Any] = {"holes": holes}
    if datums:
        part["datums"] = datums
    return yaml.safe_dump({"part": part}, sort_keys=False)


def run_import_step(args: argparse.Namespace) -> int:
    """Handler of ``holecell import-step``."""
    from cell.cad.mesh import write_stl
    from cell.cad.part import hole_rows, import_step
    from cell.config.holes_csv import write_holes_csv
    from cell.config.step_part import drawing

    part = import_step(
        args.step, mesh=args.mesh is not None, deflection_m=args.deflection_mm * 1e-3
    )
    rows = hole_rows(part)
    datums, tolerances, left = drawing(part.pmi.datums, part.pmi.tolerances)
    for r in rows:
        r.pop("tolerances", None)
        if r["id"] in tolerances:
            r["tolerances"] = tolerances[r["id"]]
    write_holes_csv(args.output, rows, args.units)
    through = sum(1 for h in part.scan.holes if h.through)
    stepped = sum(1 for h in part.scan.holes if len(h.bores) > 1)
    t = part.timings_s
    print(
        f"{args.step}: {len(rows)} holes ({through} through, {len(rows) - through} blind, "
        f"{stepped} counterbored) -> {args.output}  [read {t['read']:.2f} s, holes "
        f"{t['holes']:.2f} s]"
    )
    for reason, n in part.scan.left_out.items():
        print(f"  left out: {n} {reason}")
    pmi = part.pmi
    if not pmi.semantic:
        print("  no semantic PMI in the file: no datums or tolerances imported")
        for line in pmi.unmodelled:
            print(f"    - {line}")
    else:
        n_pos = sum(1 for v in tolerances.values() if "position" in v)
        n_size = sum(1 for v in tolerances.values() if "size" in v)
        frame = "|".join(d["label"] for d in datums) or "none"
        print(
            f"  PMI: datum frame {frame}, {n_pos} position and {n_size} size tolerances kept; "
            f"{len(pmi.unmodelled) + len(left)} not modelled:"
        )
        for line in [*pmi.unmodelled, *left]:
            print(f"    - {line}")
        for line in pmi.notes:
            print(f"  note: {line}")
    if args.yaml:
        Path(args.yaml).write_text(_part_yaml(rows, datums), encoding="utf-8")
        print(f"  part section -> {args.yaml}")
    if args.mesh and part.mesh is not None:
        write_stl(part.mesh, args.mesh)
        print(
            f"  mesh: {len(part.mesh.faces)} triangles at {args.deflection_mm:g} mm "
            f"deflection -> {args.mesh} (metres: mesh: {{path: {args.mesh}, scale: 1}}) "
            f"[{t['mesh']:.2f} s]"
        )
    return 0
