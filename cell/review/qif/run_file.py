"""``report.qif`` of a run directory: the writer's inputs taken from the run's store."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import yaml
from pydantic import ValidationError

from cell.config import CellConfig, parse_cell
from cell.errors import ConfigError
from cell.records.hole_result import HoleResult
from cell.review.qif.document import write_qif
from cell.review.qif.features import HoleNominal


def hole_nominals(info: Mapping[str, Any], where: str) -> dict[str, HoleNominal]:
    """Hole id -> the hole (part frame) from the cell file stored with the run (``info``: the
    store's run row). Only the schema is checked (the run checked the rest when it
    started, and a mesh moved since must not stop a report); a holes CSV is read again."""
    try:
        cfg = CellConfig.model_validate(yaml.safe_load(info["cell_text"]))
    except ValidationError as exc:
        first = exc.errors()[0]
        field = ".".join(str(p) for p in first["loc"])
        raise ConfigError(where, [(field, None, f"the run's cell file: {first['msg']}")]) from None
    except yaml.YAMLError as exc:
        first = str(exc).splitlines()[0]
        raise ConfigError(where, [("(yaml)", None, f"the run's cell file: {first}")]) from None
    if cfg.part.holes_csv is not None or cfg.part.step is not None:
        path = Path(info["cell_path"]) if info.get("cell_path") else None
        cfg = parse_cell(info["cell_text"], where, path)
    return {h.id: HoleNominal(h.position, h.normal, h.diameter) for h in cfg.part.holes}


def write_run_qif(
    report: Mapping[str, Any],
    run_dir: str | Path,
    info: Mapping[str, Any],
    results: Sequence[HoleResult],
) -> Path:
    """Write ``run_dir/report.qif`` from the report.json mapping ``report``; the holes' nominals
    come from the cell file stored with the run (report.json has no axes, and lists the stored
    holes only), the measured axes from the hole results."""
    nominal = hole_nominals(info, f"{run_dir} (cell)")
    measured = {r.hole_id: r.normal_part for r in results if r.normal_part is not None}
    return write_qif(report, Path(run_dir) / "report.qif", nominal, measured)
