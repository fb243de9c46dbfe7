"""Starting and resuming runs from files, refusing inputs that do not belong together.

A tour is refused when it was planned for another cell (name or SHA-256 of the cell file text),
another robot model or other joint names, when its trajectory is not (N, 6), or when a stop is
not on the trajectory or names a hole the cell does not have. A resumed run reads the cell and
both tours from its own store, so it continues exactly what was started.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

from cell.config import CellConfig, parse_cell
from cell.config.tours import check_tour
from cell.errors import CellError
from cell.review.store import FILENAME, Store
from planner import Tour
from planner.planner import cell_sha256
from planner.tour import tour_from_dict


def check_new_run_dir(out: str | Path, resumable: bool = True) -> None:
    """Refuse ``out`` as the directory of a new run when it is a file or holds a run already
    (checked before anything is planned, connected or written). ``resumable``: the command can
    continue a stored run (``holecell run --resume``), so the message says so."""
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise CellError(f"--out {out}: exists and is not a directory; give a new directory")
    if (out / FILENAME).exists():
        hint = f"continue it with holecell run --resume {out}, or " if resumable else ""
        raise CellError(f"--out {out}: a run is stored here already; {hint}give another --out")


@dataclass
class RunFiles:
    """What a run needs from files: the cell, the tours and the store."""

    cell: CellConfig
    tour: Tour
    reference: Tour | None
    store: Store


def start_run(
    run_dir: str | Path,
    cell: CellConfig,
    tour: Tour,
    tour_where: str,
    port: str,
    reference: Tour | None = None,
) -> RunFiles:
    """Check the inputs, then create the store of a new run in ``run_dir``."""
    check_tour(tour, cell, tour_where)
    if reference is not None:
        check_tour(reference, cell, "reference tour", reference=True)
    holes = {h.id: h for h in cell.part.holes}
    planned = [
        (s.hole_id, k, {"position_part_m": list(holes[s.hole_id].position),
                        "diameter_m": holes[s.hole_id].diameter})
        for k, s in enumerate(tour.stops)
    ]  # fmt: skip
    store = Store.create(
        run_dir,
        cell_name=cell.name,
        cell_sha256=cell_sha256(cell),
        cell_text=cell.raw_text,
        cell_path=str(cell.source_path or ""),
        tour_text=json.dumps(tour.to_dict()),
        reference_text=json.dumps(reference.to_dict()) if reference is not None else "",
        robot_model=cell.robot.model,
        port=port,
        holes=planned,
    )
    return RunFiles(cell, tour, reference, store)


def resume_run(run_dir: str | Path) -> RunFiles:
    """Reopen ``run_dir``: the cell and tours come from its store, checked again."""
    store = Store.open(run_dir)
    try:
        info = store.run_info()
        where = f"{store.path}"
        path = Path(info["cell_path"]) if info["cell_path"] else None
        cell = parse_cell(info["cell_text"], f"{where} (cell)", path)
        tour = tour_from_dict(json.loads(info["tour_text"]), f"{where} (tour)")
        reference = None
        if info["reference_text"]:
            reference = tour_from_dict(json.loads(info["reference_text"]), f"{where} (reference)")
        check_tour(tour, cell, f"{where} (tour)")
    except BaseException:
        store.close()
        raise
    return RunFiles(cell, tour, reference, store)
