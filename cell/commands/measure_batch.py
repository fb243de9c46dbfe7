"""``holecell measure --pairs DIR|LIST``: many stereo pairs in one process (one import, one
calibration load), a progress bar on stderr, one row per pair to CSV or JSON.

Pairing (decided here, documented in docs/measure.md):

- ``DIR`` with ``left/`` and ``right/`` subfolders: files of the same name in both are a pair,
  its id the file name without extension.
- any other ``DIR``: image files whose name (without extension) starts or ends with ``left`` /
  ``right`` (any case; a ``_``, ``-``, ``.`` or space next to it is dropped): ``H01_left.png`` +
  ``H01_right.png``, ``left_H01.png`` + ``right_H01.png``, ``left01.jpg`` + ``right01.jpg``;
  the rest of the name is the id; else ``left``/``right`` as a word inside the name, between a
  separator and a digit or separator (``raw_left1.png`` + ``raw_right1.png`` → ``raw_1``).
  Other files are ignored.
- a list file: one pair per line, ``LEFT RIGHT [ID]`` (shell quoting for spaces), ``#``
  comments and blank lines ignored, relative paths relative to the list file.

A pair that cannot be measured (a missing partner, an unreadable image, a refused measurement)
gets its reason in its row; the batch goes on. Not a subcommand (not in ``COMMAND_MODULES``).
"""

from __future__ import annotations

import argparse
import csv
import io
import json
import re
import shlex
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from cell.commands.run_progress import bar
from cell.errors import CellError
from measure import MeasureOptions, StereoCalibration, measure_hole
from measure.image_input import read_image
from robots.files import write_text_atomic

IMAGE_SUFFIXES = (".png", ".tif", ".tiff", ".jpg", ".jpeg", ".bmp", ".pgm", ".ppm")
_SIDE = re.compile(
    r"^(?:(?P<pre>left|right)[_\-. ]?(?P<a>.*)|(?P<b>.*?)[_\-. ]?(?P<post>left|right))$", re.I
)
# ``raw_left1`` / ``raw_right1`` (the ZED tools' names): the side as a word inside the name,
# after a separator and before a digit or a separator; the id keeps the rest (``raw_1``).
_SIDE_INSIDE = re.compile(r"^(?P<a>.+?[_\-. ])(?P<side>left|right)(?P<b>(?=[0-9_\-. ]).+)$", re.I)

CSV_COLUMNS = (
    "id",
    "left",
    "right",
    "status",
    "reason",
    "diameter_m",
    "center_x_m",
    "center_y_m",
    "center_z_m",
    "normal_x",
    "normal_y",
    "normal_z",
    "rms_m",
    "n_points",
    "n_rejected",
    "n_filled",
    "time_s",
    "rms_um",
    "suspect_reasons",
    "rim",
)


@dataclass(frozen=True)
class PairEntry:
    """One pair to measure: ``left``/``right`` paths (``None`` when missing) or a ``problem``."""

    pair_id: str
    left: Path | None
    right: Path | None
    problem: str = ""


def _side_and_id(stem: str) -> tuple[str, str] | None:
    m = _SIDE.match(stem)
    if not m:
        inside = _SIDE_INSIDE.match(stem)
        if inside is None:
            return None
        return inside.group("side").lower(), inside.group("a") + inside.group("b")
    if m.group("pre"):
        return m.group("pre").lower(), m.group("a")
    return m.group("post").lower(), m.group("b")


def _images(folder: Path) -> list[Path]:
    return sorted(p for p in folder.iterdir() if p.is_file() and p.suffix.lower() in IMAGE_SUFFIXES)


def pairs_in_dir(folder: Path) -> list[PairEntry]:
    """The pairs of a folder (``left/``+``right/`` subfolders, or left/right in the names)."""
    sides: dict[str, dict[str, Path]] = {}
    if (folder / "left").is_dir() and (folder / "right").is_dir():
        for side in ("left", "right"):
            for p in _images(folder / side):
                sides.setdefault(p.stem, {})[side] = p
    else:
        for p in _images(folder):
            hit = _side_and_id(p.stem)
            if hit is not None:
                side, pair_id = hit
                sides.setdefault(pair_id or p.stem, {})[side] = p
    out = []
    for pair_id in sorted(sides):
        got = sides[pair_id]
        missing = [s for s in ("left", "right") if s not in got]
        problem = f"no {missing[0]} image" if missing else ""
        out.append(PairEntry(pair_id, got.get("left"), got.get("right"), problem))
    return out


def pairs_in_list(path: Path) -> list[PairEntry]:
    """The pairs of a list file: ``LEFT RIGHT [ID]`` per line."""
    out = []
    base = path.parent
    for n, line in enumerate(path.read_text().splitlines(), start=1):
        try:
            fields = shlex.split(line, comments=True)
        except ValueError as exc:
            out.append(PairEntry(f"line {n}", None, None, f"{path}: line {n}: {exc}"))
            continue
        if not fields:
            continue
        if len(fields) not in (2, 3):
            out.append(
                PairEntry(
                    f"line {n}",
                    None,
                    None,
                    f"{path}: line {n}: expected LEFT RIGHT [ID], got {len(fields)} fields",
                )
            )
            continue
        left, right = (base / f if not Path(f).is_absolute() else Path(f) for f in fields[:2])
        pair_id = fields[2] if len(fields) == 3 else Path(fields[0]).stem
        out.append(PairEntry(pair_id, left, right))
    return out


def collect_pairs(source: str) -> list[PairEntry]:
    """Pairs from a folder or a list file; raises ``FileNotFoundError`` when neither."""
    p = Path(source)
    if p.is_dir():
        return pairs_in_dir(p)
    if p.is_file():
        return pairs_in_list(p)
    raise FileNotFoundError(f"{source}: no such folder or list file")


def _row(entry: PairEntry) -> dict[str, Any]:
    row: dict[str, Any] = dict.fromkeys(CSV_COLUMNS, "")
    row.update(
        id=entry.pair_id,
        left="" if entry.left is None else str(entry.left),
        right="" if entry.right is None else str(entry.right),
    )
    return row


def measure_pairs(entries, stereo, diameter_m, opts, progress=None) -> list[dict[str, Any]]:
    """Measure each entry; a failure is the row's ``status: error`` with its reason."""
    rows = []
    for k, entry in enumerate(entries):
        row = _row(entry)
        result: dict[str, Any] = {}
        if entry.problem:
            row.update(status="error", reason=entry.problem)
        else:
            try:
                left = read_image(str(entry.left), "left")
                right = read_image(str(entry.right), "right")
                m = measure_hole(left, right, stereo, expected_diameter_m=diameter_m, options=opts)
            except Exception as exc:  # a bad pair must not stop the batch
                row.update(status="error", reason=str(exc) or type(exc).__name__)
            else:
                result = m.to_dict()
                row.update(
                    status=m.status,
                    diameter_m=m.diameter_m,
                    rms_m=m.rms_m,
                    n_points=m.n_points,
                    n_rejected=m.n_rejected,
                    n_filled=m.n_filled,
                    time_s=m.time_s,
                    rms_um=m.rms_m * 1e6,
                    suspect_reasons="; ".join(m.suspect_reasons),
                    rim="" if m.rim is None else m.rim.describe(),
                )
                for axis, c, n in zip("xyz", m.center_m, m.normal, strict=True):
                    row[f"center_{axis}_m"] = float(c)
                    row[f"normal_{axis}"] = float(n)
        row["_result"] = result
        rows.append(row)
        if progress is not None:
            progress(k + 1, len(entries), row)
    return rows


def to_csv(rows: list[dict[str, Any]]) -> str:
    """The rows as CSV text (SI units, column names carry them)."""
    buf = io.StringIO()
    w = csv.DictWriter(buf, fieldnames=CSV_COLUMNS, extrasaction="ignore", lineterminator="\n")
    w.writeheader()
    for row in rows:
        w.writerow({k: (repr(v) if isinstance(v, float) else v) for k, v in row.items()})
    return buf.getvalue()


def to_json(rows: list[dict[str, Any]], stereo_path: str) -> str:
    """The rows as a ``holecell.measure_batch`` JSON document."""
    items = []
    for row in rows:
        item = {"id": row["id"], "left": row["left"], "right": row["right"]}
        if row["status"] == "error":
            item.update(status="error", reason=row["reason"])
        else:
            item.update(row["_result"])
        items.append(item)
    doc = {"format": "holecell.measure_batch", "version": 1, "stereo": stereo_path, "pairs": items}
    return json.dumps(doc, indent=1) + "\n"


def _progress(stream):
    tty = stream.isatty()

    def show(done: int, total: int, row: dict[str, Any]) -> None:
        text = f"pairs {bar(done, total)} {done}/{total}  {row['id'][:24]:<24} {row['status']}"
        if tty:
            end = "\n" if done == total else ""
            print("\r\x1b[2K" + text, end=end, file=stream, flush=True)
        else:
            print(text, file=stream, flush=True)

    return show


def run_batch(args: argparse.Namespace) -> int:
    """Handler of ``holecell measure --pairs``: 0 all measured, 1 some pairs failed."""
    t0 = time.perf_counter()
    if args.output and Path(args.output).suffix.lower() not in (".csv", ".json"):
        raise CellError(f"-o {args.output}: the rows file must end in .csv or .json")
    opts = MeasureOptions.published() if args.method == "published" else MeasureOptions()
    stereo = StereoCalibration.load(args.stereo)
    entries = collect_pairs(args.pairs)
    if not entries:
        raise FileNotFoundError(f"{args.pairs}: no image pairs found (see --help for the naming)")
    rows = measure_pairs(entries, stereo, args.diameter, opts, _progress(sys.stderr))
    if args.output:
        out = Path(args.output)
        text = to_json(rows, args.stereo) if out.suffix.lower() == ".json" else to_csv(rows)
        write_text_atomic(out, text)
    if args.json:
        print(to_json(rows, args.stereo), end="")
    else:
        _print_table(rows)
    bad = sum(r["status"] == "error" for r in rows)
    spent = sum(r["time_s"] for r in rows if r["time_s"] != "")
    print(
        f"{len(rows)} pairs: {len(rows) - bad} measured, {bad} failed; "
        f"{time.perf_counter() - t0:.2f} s in all, {spent:.2f} s measuring"
        + (f"; wrote {args.output}" if args.output else ""),
        file=sys.stderr if args.json else sys.stdout,
    )
    return 1 if bad else 0


def _print_table(rows: list[dict[str, Any]]) -> None:
    width = max(len("id"), *(len(r["id"]) for r in rows))
    print(f"{'id':<{width}}  status   diameter mm   rms µm  reason")
    for r in rows:
        if r["status"] == "error":
            print(f"{r['id']:<{width}}  error    {'':>11}  {'':>7}  {r['reason']}")
        else:
            d, rms = r["diameter_m"] * 1e3, r["rms_m"] * 1e6
            why = r["suspect_reasons"]
            print(f"{r['id']:<{width}}  {r['status']:<7}  {d:11.4f}  {rms:7.2f}  {why}".rstrip())
