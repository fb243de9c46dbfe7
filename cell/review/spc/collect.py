"""The runs of an SPC study and each characteristic's series across them, from ``report.qif``.

A path given is a run directory (it holds ``report.qif``) or a folder whose sub-folders are run
directories. Runs are ordered by their time stamp (the run's start, written into every
characteristic measurement), then by path. Why report.qif and not results.sqlite: it is the
file that carries the evaluated characteristics with their tolerances, values, U and status
in one standard place (the store holds holes, not characteristics), and it is what a quality
department's own statistics tools read; every file is validated against the QIF schemas first.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from cell.review.qif.read import CharacteristicResult, QifResults, read_qif
from cell.review.spc.errors import SpcError


@dataclass(frozen=True)
class Point:
    """One run's value of a characteristic (m); value None: not evaluated in that run."""

    run: str
    timestamp: str | None
    value_m: float | None
    U_m: float | None
    status: str


@dataclass(frozen=True)
class Series:
    """A characteristic across runs, with the tolerance of its first run (m). ``lsl`` / ``usl``
    are absolute limits; position: no lower limit, the zone diameter as upper one."""

    name: str
    kind: str
    lsl: float | None
    usl: float | None
    points: list[Point]


def find_runs(paths: Sequence[str | Path]) -> list[Path]:
    """The ``report.qif`` files of ``paths`` (run directories or folders of them)."""
    files: list[Path] = []
    for p in map(Path, paths):
        if (p / "report.qif").is_file():
            files.append(p / "report.qif")
        elif p.is_dir() and (inner := sorted(p.glob("*/report.qif"))):
            files += inner
        elif p.is_dir():
            raise SpcError(f"{p}: no report.qif in it or in its sub-folders")
        elif not p.exists():
            raise SpcError(f"{p}: no such file or folder")
        else:
            raise SpcError(f"{p}: a file, not a run directory (give the folder holding report.qif)")
    if not files:
        raise SpcError("no runs given")
    return files


def read_runs(paths: Sequence[str | Path]) -> list[QifResults]:
    """Every run's results, in run order (time stamp, then path)."""
    runs = [read_qif(f) for f in find_runs(paths)]
    return sorted(runs, key=lambda r: (r.timestamp or "", r.path))


def _limits(c: CharacteristicResult) -> tuple[float | None, float | None]:
    return c.lsl_m, c.usl_m


def series(runs: Sequence[QifResults]) -> list[Series]:
    """One series per characteristic name, in the first run's order. A characteristic whose
    tolerance differs between runs is refused (the runs do not inspect the same drawing)."""
    out: dict[str, Series] = {}
    for r in runs:
        run = str(Path(r.path).parent)
        for c in r.characteristics:
            lsl, usl = _limits(c)
            s = out.setdefault(c.name, Series(c.name, c.kind, lsl, usl, []))
            if (s.lsl, s.usl) != (lsl, usl):
                raise SpcError(
                    f"{r.path}: {c.name}: tolerance {lsl}..{usl} m differs from "
                    f"{s.lsl}..{s.usl} m of the earlier runs"
                )
            s.points.append(Point(run, r.timestamp, c.value_m, c.U_m, c.status))
    return list(out.values())
