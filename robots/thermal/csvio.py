"""The two CSV formats of the thermal model. Column names carry their units.

Observations (``holecell thermal identify``), one row per measurement:

    time_s, target_id, q1_rad..q6_rad, temp_<sensor>_degC (one or more), x_tcp_m, y_tcp_m, z_tcp_m

Poses (``holecell thermal predict``), one row per pose:

    q1_rad..q6_rad, temp_<sensor>_degC (every sensor of the model); other columns are kept

Temperatures may also be given in kelvin (``temp_<sensor>_K``). Any other unit on
a known quantity (``x_tcp_mm``, ``q1_deg``, ``time_min``) is refused with a
message naming the column and the unit expected.
"""

from __future__ import annotations

import csv
import io
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from robots.files import write_text_atomic
from robots.thermal.errors import ThermalDataError
from robots.thermal.observations import Observations

Array = NDArray[np.float64]

JOINT_COLUMNS: tuple[str, ...] = tuple(f"q{i}_rad" for i in range(1, 7))
POSITION_COLUMNS: tuple[str, ...] = ("x_tcp_m", "y_tcp_m", "z_tcp_m")
_TEMP = re.compile(r"^temp_(?P<name>[A-Za-z0-9][A-Za-z0-9_]*?)_(?P<unit>[A-Za-z]+)$")
_TEMP_UNITS = {"degC": 0.0, "K": -273.15}
#: (pattern of a quantity with any unit, the only accepted column spelling, what it means)
_UNIT_RULES: tuple[tuple[re.Pattern[str], str, str], ...] = (
    (re.compile(r"^time_(?P<unit>\w+)$"), "time_s", "seconds"),
    (re.compile(r"^q(?P<i>[1-6])_(?P<unit>\w+)$"), "q{i}_rad", "radians"),
    (re.compile(r"^(?P<ax>[xyz])_tcp_(?P<unit>\w+)$"), "{ax}_tcp_m", "metres"),
)


@dataclass(frozen=True)
class PoseRows:
    """Rows of a poses CSV: joints (N, 6) rad, temperatures (N, S) degC, all cells as read."""

    q_rad: Array
    temps_degC: Array  # noqa: N815 (unit suffix)
    sensor_names: tuple[str, ...]
    header: tuple[str, ...]
    rows: tuple[tuple[str, ...], ...]


def _read(path: str | Path) -> tuple[list[str], list[list[str]]]:
    p = Path(path)
    if p.is_dir():
        raise ThermalDataError(str(path), "is a directory, not a CSV file")
    if not p.is_file():
        raise ThermalDataError(str(path), "no such file")
    try:
        with p.open(newline="", encoding="utf-8") as fh:
            table = [row for row in csv.reader(fh) if any(cell.strip() for cell in row)]
    except UnicodeDecodeError as exc:
        raise ThermalDataError(
            str(path), f"not a UTF-8 text file ({exc.reason} at byte {exc.start})"
        ) from exc
    if not table:
        raise ThermalDataError(str(path), "the file is empty; expected a header row")
    header = [h.strip() for h in table[0]]
    dupes = sorted({h for h in header if header.count(h) > 1})
    if dupes:
        raise ThermalDataError(str(path), f"repeated columns {dupes}", line=1)
    if len(table) < 2:
        raise ThermalDataError(str(path), "no data rows after the header")
    return header, table[1:]


def _check_units(path: str, header: list[str]) -> None:
    for col in header:
        for pattern, spelling, meaning in _UNIT_RULES:
            m = pattern.match(col)
            if m:
                want = spelling.format(**m.groupdict())
                if col != want:
                    raise ThermalDataError(
                        path,
                        f"unit {m['unit']!r} not accepted: the column must be {want!r} ({meaning})",
                        line=1,
                        column=col,
                    )
        m = _TEMP.match(col)
        if m and m["unit"] not in _TEMP_UNITS:
            raise ThermalDataError(
                path,
                f"temperature unit {m['unit']!r} not accepted: use 'temp_{m['name']}_degC' "
                f"(degrees Celsius) or 'temp_{m['name']}_K' (kelvin)",
                line=1,
                column=col,
            )


def _temperature_columns(header: list[str]) -> list[tuple[str, str, float]]:
    """``(column, sensor name, offset to degC)`` for every temperature column, in file order."""
    out = []
    for col in header:
        m = _TEMP.match(col)
        if m and m["unit"] in _TEMP_UNITS:
            out.append((col, m["name"], _TEMP_UNITS[m["unit"]]))
    return out


def _require(path: str, header: list[str], columns: tuple[str, ...] | list[str]) -> None:
    missing = [c for c in columns if c not in header]
    if missing:
        raise ThermalDataError(path, f"missing columns {missing}; the header has {header}", line=1)


def _floats(path: str, header: list[str], rows: list[list[str]], columns: list[str]) -> Array:
    idx = [header.index(c) for c in columns]
    out = np.empty((len(rows), len(columns)))
    for r, row in enumerate(rows):
        for j, (c, i) in enumerate(zip(columns, idx, strict=True)):
            cell = row[i].strip() if i < len(row) else ""
            try:
                value = float(cell)
            except ValueError:
                raise ThermalDataError(
                    path, f"{cell!r} is not a number", line=r + 2, column=c
                ) from None
            if not np.isfinite(value):
                raise ThermalDataError(path, f"{cell!r} is not finite", line=r + 2, column=c)
            out[r, j] = value
    return out


def _temperatures(path: str, header: list[str], rows: list[list[str]]) -> tuple[Array, list[str]]:
    temp_cols = _temperature_columns(header)
    if not temp_cols:
        raise ThermalDataError(
            path, "no temperature column; expected one or more 'temp_<sensor>_degC'", line=1
        )
    names = [n for _, n, _ in temp_cols]
    dupes = sorted({n for n in names if names.count(n) > 1})
    if dupes:
        raise ThermalDataError(path, f"sensors {dupes} appear in more than one column", line=1)
    temps = _floats(path, header, rows, [c for c, _, _ in temp_cols])
    return temps + np.array([off for _, _, off in temp_cols]), names


def read_observations(path: str | Path, known_targets: set[str] | None = None) -> Observations:
    """Read an observations CSV; ``known_targets`` (the cell's reference target ids) checks ids."""
    src = str(path)
    header, rows = _read(path)
    _check_units(src, header)
    _require(src, header, ["time_s", "target_id", *JOINT_COLUMNS, *POSITION_COLUMNS])
    time_s = _floats(src, header, rows, ["time_s"])[:, 0]
    q = _floats(src, header, rows, list(JOINT_COLUMNS))
    p = _floats(src, header, rows, list(POSITION_COLUMNS))
    temps, names = _temperatures(src, header, rows)
    ti = header.index("target_id")
    ids = []
    for r, row in enumerate(rows):
        tid = row[ti].strip() if ti < len(row) else ""
        if not tid:
            raise ThermalDataError(src, "empty target id", line=r + 2, column="target_id")
        if known_targets is not None and tid not in known_targets:
            known = ", ".join(sorted(known_targets)) or "none"
            raise ThermalDataError(
                src,
                f"unknown target id {tid!r} (the cell's reference targets: {known})",
                line=r + 2,
                column="target_id",
            )
        ids.append(tid)
    return Observations(
        time_s=time_s,
        target_ids=tuple(ids),
        q_rad=q,
        temps_degC=temps,
        sensor_names=tuple(names),
        p_tcp_m=p,
        source=src,
        lines=tuple(range(2, len(rows) + 2)),
    )


def write_observations(path: str | Path, obs: Observations) -> None:
    """Write observations in the CSV format :func:`read_observations` reads (atomically)."""
    temp_cols = [f"temp_{n}_degC" for n in obs.sensor_names]
    buf = io.StringIO()
    w = csv.writer(buf)
    w.writerow(["time_s", "target_id", *JOINT_COLUMNS, *temp_cols, *POSITION_COLUMNS])
    for i in range(len(obs)):
        w.writerow(
            [repr(float(obs.time_s[i])), obs.target_ids[i]]
            + [repr(float(v)) for v in obs.q_rad[i]]
            + [repr(float(v)) for v in obs.temps_degC[i]]
            + [repr(float(v)) for v in obs.p_tcp_m[i]]
        )
    write_text_atomic(path, buf.getvalue())


def read_poses(
    path: str | Path, sensor_names: tuple[str, ...], used: tuple[str, ...] | None = None
) -> PoseRows:
    """Read a poses CSV: the joints and a temperature column for each sensor in ``used``.

    ``used`` (default: all of ``sensor_names``) are the sensors the model reads; the
    other sensors' temperatures are NaN when their column is absent.
    """
    src = str(path)
    header, rows = _read(path)
    _check_units(src, header)
    _require(src, header, list(JOINT_COLUMNS))
    temp_cols = {n: (c, off) for c, n, off in _temperature_columns(header)}
    used = sensor_names if used is None else used
    missing = [f"temp_{n}_degC" for n in used if n not in temp_cols]
    if missing:
        raise ThermalDataError(
            src, f"missing temperature columns {missing} (the model's sensors)", line=1
        )
    q = _floats(src, header, rows, list(JOINT_COLUMNS))
    temps = np.full((len(rows), len(sensor_names)), np.nan)
    for j, n in enumerate(sensor_names):
        if n in temp_cols:
            col, offset = temp_cols[n]
            temps[:, j] = _floats(src, header, rows, [col])[:, 0] + offset
    width = len(header)
    return PoseRows(
        q_rad=q,
        temps_degC=temps,
        sensor_names=tuple(sensor_names),
        header=tuple(header),
        rows=tuple(tuple((list(r) + [""] * width)[:width]) for r in rows),
    )
