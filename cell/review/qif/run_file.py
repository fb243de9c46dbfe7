"""``report.qif`` of a run directory: the writer's inputs taken from the run's store."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from cell.config import parse_cell
from cell.review.qif.document import write_qif
from cell.run.results import HoleResult


def write_run_qif(
    report: Mapping[str, Any],
    run_dir: str | Path,
    info: Mapping[str, Any],
    results: Sequence[HoleResult],
) -> Path:
    """Write ``run_dir/report.qif`` from the report.json mapping ``report``; the nominal axes
    come from the cell file stored with the run (``info``: the store's run row), the measured
    axes from the hole results."""
    path = Path(info["cell_path"]) if info.get("cell_path") else None
    cell = parse_cell(info["cell_text"], f"{run_dir} (cell)", path)
    nominal = {h.id: h.normal for h in cell.part.holes}
    measured = {r.hole_id: r.normal_part for r in results if r.normal_part is not None}
    return write_qif(report, Path(run_dir) / "report.qif", nominal, measured)
