"""Reading the cell file: YAML text or a path -> a checked :class:`CellConfig`, every problem
reported with the file name, the field path and the value."""

from __future__ import annotations

import functools
from pathlib import Path
from typing import TYPE_CHECKING

import yaml
from pydantic import ValidationError

from cell.config.checks import cell_problems
from cell.config.datum_checks import gdt_problems
from cell.config.datums import Datum
from cell.config.holes_csv import read_holes_csv
from cell.config.problems import pydantic_problems
from cell.config.schema import (
    CellConfig,
    Hole,
)
from cell.config.yaml_problem import yaml_problem
from cell.errors import ConfigError

if TYPE_CHECKING:
    from cell.cad.part import ImportedPart

DATA_DIR = Path(__file__).parents[1] / "data"
BUILTIN_CELLS = ("motorcycle_frame",)


def _with_csv_holes(
    cfg: CellConfig, source: str, source_path: Path | None, text: str
) -> CellConfig:
    """The cell with the holes of ``part.holes_csv`` appended to ``part.holes``."""
    csv_path = Path(cfg.part.holes_csv or "")
    if not csv_path.is_absolute() and cfg.base_dir is not None:
        csv_path = cfg.base_dir / csv_path
    rows = read_holes_csv(csv_path)
    seen = {h.id for h in cfg.part.holes}
    for n, row in enumerate(rows, start=2):
        if row["id"] in seen:
            raise ConfigError(str(csv_path), [(f"row {n}, column 'id'", row["id"], "duplicate id")])
        seen.add(str(row["id"]))
    try:
        extra = [Hole.model_validate(r) for r in rows]
    except ValidationError as exc:
        raise ConfigError(str(csv_path), pydantic_problems(exc)) from exc
    part = cfg.part.model_copy(update={"holes": [*cfg.part.holes, *extra]})
    out = cfg.model_copy(update={"part": part})
    out._source_path = source_path
    out._raw_text = text
    return out


@functools.lru_cache(maxsize=4)
def _imported(path: str, stamp: int, mesh: bool, deflection_m: float) -> ImportedPart:
    """A STEP file imported, kept while it is unchanged (a cell is loaded many times)."""
    from cell.cad.part import import_step

    del stamp  # part of the key only
    return import_step(path, mesh=mesh, deflection_m=deflection_m)


def _with_step(cfg: CellConfig, source_path: Path | None, text: str) -> CellConfig:
    """The cell with the holes (and drawing, and mesh) of ``part.step`` (docs/cad_import.md)."""
    from cell.cad.part import hole_rows  # OpenCascade: only for cells with a STEP
    from cell.config.step_part import drawing

    spec = cfg.part.step
    assert spec is not None
    path = Path(spec.path)
    if not path.is_absolute() and cfg.base_dir is not None:
        path = cfg.base_dir / path
    if not path.is_file():
        raise ConfigError(str(path), [("part.step.path", spec.path, "no such file")])
    part = _imported(str(path.resolve()), path.stat().st_mtime_ns, spec.mesh, spec.deflection_m)
    rows = hole_rows(part)
    datums, tolerances, _ = drawing(part.pmi.datums, part.pmi.tolerances)
    use_pmi = spec.pmi and not cfg.part.datums
    seen = {h.id for h in cfg.part.holes}
    holes = []
    for row in rows:
        if row["id"] in seen:
            raise ConfigError(str(path), [("part.step: hole id", row["id"], "given twice")])
        hole = {k: row[k] for k in ("id", "position", "normal", "diameter")}
        if use_pmi and row["id"] in tolerances:
            hole["tolerances"] = tolerances[row["id"]]
        holes.append(Hole.model_validate(hole))
    update: dict[str, object] = {"holes": [*cfg.part.holes, *holes]}
    if use_pmi and datums:
        update["datums"] = [Datum.model_validate(d) for d in datums]
    out = cfg.model_copy(update={"part": cfg.part.model_copy(update=update)})
    out._source_path = source_path
    out._raw_text = text
    out._step_mesh = part.mesh
    return out


def parse_cell(text: str, source: str = "<cell>", source_path: Path | None = None) -> CellConfig:
    """Validate a cell file's YAML text; raises :class:`ConfigError` listing every problem."""
    try:
        data = yaml.safe_load(text)
    except yaml.YAMLError as exc:
        raise ConfigError(source, [yaml_problem(exc)]) from None
    if not isinstance(data, dict):
        raise ConfigError(source, [("(top level)", data, "a cell file is a mapping of keys")])
    try:
        cfg = CellConfig.model_validate(data)
    except ValidationError as exc:
        raise ConfigError(source, pydantic_problems(exc)) from exc
    cfg._source_path = source_path
    cfg._raw_text = text
    if cfg.part.holes_csv is not None:
        cfg = _with_csv_holes(cfg, source, source_path, text)
    if cfg.part.step is not None:
        cfg = _with_step(cfg, source_path, text)
    problems = gdt_problems(cfg) or cell_problems(cfg)
    if problems:
        raise ConfigError(source, problems)
    return cfg


def builtin_cell_path(name: str = "motorcycle_frame") -> Path:
    """Path of a cell file shipped with the package."""
    if name not in BUILTIN_CELLS:
        raise ConfigError(
            name, [("(name)", name, f"no built-in cell (known: {', '.join(BUILTIN_CELLS)})")]
        )
    return DATA_DIR / f"{name}.yaml"


def load_cell(path: str | Path | None = None) -> CellConfig:
    """Read and validate a cell file; ``None`` or a built-in name gives a built-in cell."""
    if path is None or str(path) in BUILTIN_CELLS:
        path = builtin_cell_path(str(path) if path else "motorcycle_frame")
    path = Path(path)
    if path.is_dir():
        raise ConfigError(str(path), [("(file)", str(path), "is a directory, not a cell file")])
    if not path.is_file():
        raise ConfigError(str(path), [("(file)", str(path), "no such file")])
    try:
        text = path.read_text(encoding="utf-8")
    except (UnicodeDecodeError, PermissionError) as exc:
        raise ConfigError(
            str(path), [("(file)", str(path), f"cannot be read as UTF-8 text: {exc}")]
        ) from exc
    return parse_cell(text, str(path), path.resolve())


def load_builtin_cell(name: str = "motorcycle_frame") -> CellConfig:
    """The built-in cell ``name``."""
    return load_cell(builtin_cell_path(name))
