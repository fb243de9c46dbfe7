"""Holes from a CSV file next to the cell file (``part.holes_csv: holes.csv``).

One row per hole, in the part frame; column names carry their units, as in the thermal
CSVs (``docs/thermal.md``):

    id, x_<u>, y_<u>, z_<u>, nx, ny, nz, diameter_<u>[, tolerance_<u>]

``<u>`` is ``m``, ``mm`` or ``um`` per column (converted to metres); the normal ``nx, ny,
nz`` has no unit and must have unit length; ``tolerance`` may be left out or empty.
Another unit (``x_in``), a missing column, or a cell that is not a number is refused naming
the file, the row (1 = header) and the column.
"""

from __future__ import annotations

import csv
import math
import re
from pathlib import Path

from cell.errors import ConfigError

#: length units accepted in a column name and their factor to metres
LENGTH_UNITS = {"m": 1.0, "mm": 1e-3, "um": 1e-6}
QUANTITIES = ("x", "y", "z", "diameter", "tolerance")
NORMAL = ("nx", "ny", "nz")
_COLUMN = re.compile(r"^(?P<q>x|y|z|diameter|tolerance)(?:_(?P<unit>\w+))?$")


def _header(path: str, header: list[str]) -> dict[str, tuple[int, float]]:
    """Column index and factor to metres of every quantity; refuses bad units."""
    found: dict[str, tuple[int, float]] = {}
    for k, col in enumerate(header):
        m = _COLUMN.match(col)
        if m is None:
            continue
        unit = m["unit"]
        if unit not in LENGTH_UNITS:
            shown = f"unit {unit!r}" if unit else "no unit"
            raise ConfigError(
                path,
                [
                    (
                        f"row 1, column {col!r}",
                        col,
                        f"{shown} not accepted: write {m['q']}_m, {m['q']}_mm or {m['q']}_um",
                    )
                ],
            )
        if m["q"] in found:
            raise ConfigError(path, [(f"row 1, column {col!r}", col, f"{m['q']} given twice")])
        found[m["q"]] = (k, LENGTH_UNITS[unit])
    missing = [q for q in ("x", "y", "z", "diameter") if q not in found]
    missing += [n for n in ("id", *NORMAL) if n not in header]
    if missing:
        raise ConfigError(
            path, [("row 1", header, f"missing columns {missing} (e.g. x_mm, nx, diameter_mm)")]
        )
    return found


def _number(path: str, row: int, col: str, text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not math.isfinite(value):
        raise ConfigError(path, [(f"row {row}, column {col!r}", text, "not a finite number")])
    return value


def read_holes_csv(path: str | Path) -> list[dict[str, object]]:
    """The holes of a CSV as cell-file hole mappings (m, part frame), in file order."""
    p = Path(path)
    where = str(p)
    if not p.is_file():
        raise ConfigError(where, [("part.holes_csv", where, "no such file")])
    try:
        with p.open(newline="", encoding="utf-8") as fh:
            table = [r for r in csv.reader(fh) if any(c.strip() for c in r)]
    except (UnicodeDecodeError, PermissionError) as exc:
        raise ConfigError(where, [("part.holes_csv", where, f"cannot be read: {exc}")]) from exc
    if len(table) < 2:
        raise ConfigError(where, [("row 1", None, "needs a header row and at least one hole")])
    header = [h.strip() for h in table[0]]
    cols = _header(where, header)
    holes = []
    for n, raw in enumerate(table[1:], start=2):
        cells = [c.strip() for c in raw] + [""] * (len(header) - len(raw))
        if len(raw) > len(header):
            raise ConfigError(
                where, [(f"row {n}", raw, f"{len(raw)} cells, header has {len(header)}")]
            )
        hole_id = cells[header.index("id")]
        if not hole_id:
            raise ConfigError(where, [(f"row {n}, column 'id'", hole_id, "empty hole id")])
        value = {
            q: _number(where, n, header[k], cells[k]) * f
            for q, (k, f) in cols.items()
            if q != "tolerance" or cells[k]
        }
        normal = [_number(where, n, c, cells[header.index(c)]) for c in NORMAL]
        norm = math.sqrt(sum(v * v for v in normal))
        if abs(norm - 1.0) > 1e-3:
            raise ConfigError(
                where, [(f"row {n}, columns nx, ny, nz", normal, f"length {norm:.6g}, not 1")]
            )
        for q in ("diameter", "tolerance"):
            if q in value and value[q] <= 0:
                col = header[cols[q][0]]
                raise ConfigError(where, [(f"row {n}, column {col!r}", value[q], "must be > 0")])
        holes.append(
            {
                "id": hole_id,
                "position": [value["x"], value["y"], value["z"]],
                "normal": normal,
                "diameter": value["diameter"],
                "tolerance": value.get("tolerance"),
            }
        )
    return holes


def write_holes_csv(path: str | Path, holes: list[dict[str, object]], unit: str = "mm") -> Path:
    """Write holes (mappings with ``id``, ``position``, ``normal``, ``diameter`` in m, and
    optionally ``tolerance`` (m) and ``extra``: more columns, ignored by :func:`read_holes_csv`)
    as a holes CSV with lengths in ``unit`` (``m``, ``mm`` or ``um``); returns the path."""
    if unit not in LENGTH_UNITS:
        raise ConfigError(str(path), [("--units", unit, "write m, mm or um")])
    f = 1.0 / LENGTH_UNITS[unit]
    extra_cols: list[str] = []
    for h in holes:
        for k in dict(h.get("extra") or {}):  # type: ignore[call-overload]
            if k not in extra_cols:
                extra_cols.append(k)
    header = ["id", f"x_{unit}", f"y_{unit}", f"z_{unit}", "nx", "ny", "nz", f"diameter_{unit}"]
    header += [f"tolerance_{unit}", *extra_cols]
    p = Path(path)
    with p.open("w", newline="", encoding="utf-8") as fh:
        out = csv.writer(fh)
        out.writerow(header)
        for h in holes:
            pos = [float(v) * f for v in h["position"]]  # type: ignore[attr-defined]
            tol = h.get("tolerance")
            extra = dict(h.get("extra") or {})  # type: ignore[call-overload]
            out.writerow(
                [h["id"], *(f"{v:.9g}" for v in pos)]
                + [f"{float(v):.12g}" for v in h["normal"]]  # type: ignore[attr-defined]
                + [f"{float(h['diameter']) * f:.9g}"]  # type: ignore[arg-type]
                + ["" if tol is None else f"{float(tol) * f:.9g}"]  # type: ignore[arg-type]
                + [extra.get(k, "") for k in extra_cols]
            )
    return p
